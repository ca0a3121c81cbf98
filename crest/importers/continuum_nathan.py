"""Import the continuum_nathan measurements (a 4-cable continuum robot with an EM tip tracker)
into crest-log/1 logs. The source format, the robot and its conventions are described in
../shared/data/continuum_nathan/PROVENANCE.md; the data is read from there and never copied
into the repository (all rights reserved by its authors: local validation only).

Conversion:
- Cables: source dl > 0 pays a cable out, crest tendon > 0 pulls it, so tendon_k = -dl_k (mm).
  Cable k sits at (k-1)*90 deg from +x, as crest's tendon k. The dl are open-loop servo commands:
  tendon_pos = tendon_cmd.
- Insertion: one 64 mm segment, never inserted: insertion_cmd = insertion_pos = 64 mm.
- Tip: x, y, z (mm) of the model frame (origin at the robot base, z along the unbent backbone,
  x toward cable 1), taken as the crest base frame. The orientation (rx, ry, rz) is not imported.
- Every sample is a static pose taken after a wait, not at a fixed rate: t = source index * 1 s
  and sample_rate_hz = 1 only order the poses.
- A tracker sample that is non-finite or beyond `MAX_PLAUSIBLE_TIP_MM` is not a measurement: the
  tip is written as missing, with a DataImportWarning and the rows listed in the sidecar.
- A row whose pose and orientation are all exactly zero is a placeholder without a measurement
  (row 0 of average_2024_05_12_18_47_41.dat): it is dropped.

Format A (``.dat`` with a six-line header) holds the commands; format B (three rows x, y, z by
M columns, no header) does not, and its commands are rebuilt from the sweep formula of PROVENANCE:
    dl = -12 * [cos phi, sin phi, -cos phi, -sin phi],  phi = direction * 2*pi * step / 128.
"""

from __future__ import annotations

import math
import re
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from crest.log.log_format import catheter_dict
from crest.log.log_writer import LogWriter

REPOSITORY = "nathanmcallister/continuum_nathan"
INSERTION_MM = 64.0
SAMPLE_PERIOD_S = 1.0
# The Aurora field generators measure within roughly half a metre of the generator: a tip
# further than 1 m from the robot base is not a measurement (row 335 of the circle sweep has 1.5e24).
MAX_PLAUSIBLE_TIP_MM = 1000.0
# 12 mm of cable gives about 90 deg of bending: r = 12 / (pi/2) ~ 7.6 mm without losses;
# the source code says 8 mm (April 2024) or 4 mm (July 2024). To be calibrated.
CATHETER = catheter_dict(flexible_length_mm=64.0, tendon_offset_mm=7.5, outer_diameter_mm=None)

_SOURCE_COMMITS = {
    "max_sweep.dat": "b6b64816a425d3a67366cd9f8f17109e30ee65e4",
    "multi_sweep.dat": "b6b64816a425d3a67366cd9f8f17109e30ee65e4",
    "multi_sweep_backwards.dat": "b6b64816a425d3a67366cd9f8f17109e30ee65e4",
    "preload_sweep.dat": "b6b64816a425d3a67366cd9f8f17109e30ee65e4",
    "data_2024_05_21_14_57_12.dat": "8d9d20da77b41642687a6b629ed0ceec9777c09f",
    "average_2024_05_12_18_47_41.dat": "21a84c466a195ee37f35fc12dc51a240e2c8fda4",
}
KNOWN_FILES = (
    "experiments/sweep/output/data_2024_05_21_14_57_12.dat",
    "experiments/model_comparison/test_data/average_2024_05_12_18_47_41.dat",
    "experiments/sweep/output/max_sweep.dat",
    "experiments/sweep/output/multi_sweep.dat",
    "experiments/sweep/output/multi_sweep_backwards.dat",
    "experiments/sweep/output/preload_sweep.dat",
)


@dataclass(frozen=True)
class SweepSpec:
    """How a format B file was commanded: ``steps`` per loop, phi increasing (+1) or decreasing (-1)."""

    steps: int
    direction: int
    amplitude_mm: float
    description: str


SWEEPS = {
    "max_sweep.dat": SweepSpec(128, +1, 12.0, "one counter-clockwise loop, 4 s wait before each sample"),
    "multi_sweep.dat": SweepSpec(128, +1, 12.0, "8 counter-clockwise loops; column = 128*repetition + step"),
    "multi_sweep_backwards.dat": SweepSpec(
        128, -1, 12.0, "8 clockwise loops, 0.5 s wait; column = 128*repetition + step; "
                       "column 462 (repetition 3, step 78) is a ~3 mm tracker blip per PROVENANCE, kept"),
    "preload_sweep.dat": SweepSpec(128, +1, 12.0, "one counter-clockwise loop under a different cable preload "
                                                  "(tip about 4 mm lower)"),
}

_HEADER_KEYS = (("date",), ("time",), ("num_cables",), ("num_auroras", "num_coils"), ("num_measurements",))
_FORMAT_A_FIELDS = ("idx", "dl1", "dl2", "dl3", "dl4", "x", "y", "z", "rx", "ry", "rz")
# nan/inf are read, so that a non-finite tracker value becomes a missing tip rather than a failed file.
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|[+-]?(?:nan|inf|infinity)", re.IGNORECASE)


class DataImportError(ValueError):
    """A source file that cannot be imported; the message names the file and, where known, the line."""

    def __init__(self, path: Path, problem: str, *, line: int | None = None) -> None:
        self.path = path
        self.line = line
        where = f"{path}, line {line}" if line is not None else str(path)
        super().__init__(f"{where}: {problem}")


class DataImportWarning(UserWarning):
    """Source rows whose tracker sample was rejected or which were dropped."""


@dataclass(frozen=True)
class _Poses:
    """Static poses of one source file in crest conventions."""

    index: np.ndarray          # [N] source row (format A) or column (format B)
    tendon_mm: np.ndarray      # [N, 4] crest tendon displacement, positive = pulled
    tip_mm: np.ndarray         # [N, 3] NaN where the tracker sample was rejected
    rejected: tuple[int, ...]  # source indices whose tip was rejected
    dropped: tuple[int, ...]   # source indices dropped as placeholders
    format_note: str


def default_data_dir() -> Path:
    """../shared/data/continuum_nathan beside the repository that holds this package, or, for an
    installed package (which lives in site-packages, beside no repository), beside the current
    directory; the first of the two that exists (the first when neither does)."""
    relative = Path("shared") / "data" / "continuum_nathan"
    candidates = [Path(__file__).resolve().parents[3] / relative, Path.cwd().resolve().parent / relative]
    return next((path for path in candidates if path.is_dir()), candidates[0])


def import_all(data_dir: Path | str, out_dir: Path | str, *, overwrite: bool = False) -> list[Path]:
    """Import every file of `KNOWN_FILES` under ``data_dir`` to ``out_dir/<stem>.csv`` (+ .json)."""
    data_dir = Path(data_dir)
    return [import_file(data_dir / relative, Path(out_dir) / f"{Path(relative).stem}.csv", overwrite=overwrite)
            for relative in KNOWN_FILES]


def import_file(source: Path | str, out_csv: Path | str, *, overwrite: bool = False) -> Path:
    """Convert one source file (format A or B, detected from its first line) into a crest log.

    Returns the CSV path. Raises DataImportError for a malformed file, naming file and line.
    """
    source = Path(source)
    text = _read_text(source)
    poses = _read_format_a(source, text) if text.lstrip().upper().startswith("DATE:") else _read_format_b(source, text)
    if poses.rejected:
        warnings.warn(f"{source}: tracker sample rejected as missing (non-finite or beyond "
                      f"{MAX_PLAUSIBLE_TIP_MM:g} mm) at source index {list(poses.rejected)}",
                      DataImportWarning, stacklevel=2)
    if poses.dropped:
        warnings.warn(f"{source}: placeholder row(s) without a measurement dropped at source index "
                      f"{list(poses.dropped)}", DataImportWarning, stacklevel=2)
    return _write_log(source, poses, Path(out_csv), overwrite)


def _read_text(path: Path) -> str:
    try:
        data = path.read_bytes()
    except OSError as error:
        raise DataImportError(path, f"cannot read the file ({error.strerror or error})") from error
    try:
        return data.decode("ascii")
    except UnicodeDecodeError as error:
        line = data[:error.start].count(b"\n") + 1
        raise DataImportError(path, "non-ASCII byte; the source files are plain ASCII numbers", line=line) from error


def _parse_number(cell: str, path: Path, line: int, field: str) -> float:
    cell = cell.strip()
    if not _NUMBER.fullmatch(cell):
        raise DataImportError(path, f"{field}: not a number: {cell[:40]!r}", line=line)
    return float(cell)


def _is_plausible_tip(xyz_mm: np.ndarray) -> bool:
    return bool(np.all(np.isfinite(xyz_mm)) and np.all(np.abs(xyz_mm) <= MAX_PLAUSIBLE_TIP_MM))


def _read_format_a(path: Path, text: str) -> _Poses:
    """Format A: six header lines, then ``idx,dl1,dl2,dl3,dl4,x,y,z,rx,ry,rz`` per pose."""
    lines = text.splitlines()
    if len(lines) < 6:
        raise DataImportError(path, f"the header has {len(lines)} of its 6 lines "
                                    "(DATE, TIME, NUM_CABLES, NUM_AURORAS, NUM_MEASUREMENTS, ---)", line=len(lines) + 1)
    header = {}
    for number, (line, keys) in enumerate(zip(lines, _HEADER_KEYS), start=1):
        key, separator, value = line.partition(":")
        if not separator or key.strip().lower() not in keys:
            raise DataImportError(path, f"expected header line '{keys[0].upper()}: ...', got {line[:40]!r}", line=number)
        header[keys[0]] = (value.strip(), number)
    if lines[5].strip() != "---":
        raise DataImportError(path, f"expected the header end '---', got {lines[5][:40]!r}", line=6)
    counts = {}
    for key, expected in (("num_cables", 4), ("num_auroras", 1), ("num_measurements", None)):
        value, number = header[key]
        if not value.isdigit() or (expected is not None and int(value) != expected):
            wanted = f"{expected}" if expected is not None else "a whole number"
            raise DataImportError(path, f"{key.upper()} must be {wanted}, got {value!r}", line=number)
        counts[key] = int(value)

    body = lines[6:]
    while body and not body[-1].strip():
        body.pop()
    if len(body) != counts["num_measurements"]:
        raise DataImportError(path, f"NUM_MEASUREMENTS says {counts['num_measurements']} rows, "
                                    f"the file has {len(body)}", line=5)

    index, tendon_mm, tip_mm, rejected, dropped = [], [], [], [], []
    for row, line in enumerate(body):
        number = row + 7
        cells = line.split(",")
        if len(cells) != len(_FORMAT_A_FIELDS):
            raise DataImportError(path, f"expected {len(_FORMAT_A_FIELDS)} values "
                                        f"({','.join(_FORMAT_A_FIELDS)}), got {len(cells)}", line=number)
        values = [_parse_number(cell, path, number, field) for cell, field in zip(cells, _FORMAT_A_FIELDS)]
        if values[0] != row:
            raise DataImportError(path, f"idx is {cells[0].strip()!r}, expected {row} (rows in order from 0)",
                                  line=number)
        dl_mm = np.array(values[1:5])
        if not np.all(np.isfinite(dl_mm)):
            raise DataImportError(path, f"dl1..dl4 must be finite commands, got {cells[1:5]}", line=number)
        tracker = np.array(values[5:11])
        if np.all(tracker == 0.0):
            dropped.append(row)
            continue
        xyz_mm = tracker[:3]
        if not (_is_plausible_tip(xyz_mm) and np.all(np.isfinite(tracker[3:]))):
            rejected.append(row)
            xyz_mm = np.full(3, np.nan)
        index.append(row)
        tendon_mm.append(-dl_mm + 0.0)  # + 0.0 turns the -0.0 of a zero dl into 0.0
        tip_mm.append(xyz_mm)
    return _Poses(index=np.array(index), tendon_mm=np.array(tendon_mm).reshape(-1, 4),
                  tip_mm=np.array(tip_mm).reshape(-1, 3), rejected=tuple(rejected), dropped=tuple(dropped),
                  format_note="Format A (.dat with header): commands as stored, tendon_k = -dl_k.")


def _read_format_b(path: Path, text: str) -> _Poses:
    """Format B: three comma-separated rows x, y, z (mm) by M columns; commands from `SWEEPS`."""
    spec = SWEEPS.get(path.name)
    if spec is None:
        raise DataImportError(path, f"neither format A (no 'DATE:' header) nor a known format B sweep; format B "
                                    f"stores no commands, so only {', '.join(SWEEPS)} can be imported")
    lines = [line for line in text.splitlines() if line.strip()]
    if len(lines) != 3:
        raise DataImportError(path, f"format B has 3 rows (x, y, z), found {len(lines)}", line=min(len(lines) + 1, 4))
    rows = []
    for number, (line, axis) in enumerate(zip(lines, "xyz"), start=1):
        cells = line.split(",")
        rows.append([_parse_number(cell, path, number, f"{axis}, column {column}") for column, cell in enumerate(cells)])
    columns = len(rows[0])
    for number, row in enumerate(rows, start=1):
        if len(row) != columns:
            raise DataImportError(path, f"row has {len(row)} columns, row 1 has {columns}", line=number)
    if columns % spec.steps:
        raise DataImportError(path, f"{columns} columns is not a whole number of {spec.steps}-step loops", line=1)

    xyz_mm = np.array(rows).T
    plausible = np.array([_is_plausible_tip(tip) for tip in xyz_mm])
    xyz_mm[~plausible] = np.nan
    index = np.arange(columns)
    phi_rad = spec.direction * 2.0 * math.pi * (index % spec.steps) / spec.steps
    dl_mm = -spec.amplitude_mm * np.stack([np.cos(phi_rad), np.sin(phi_rad), -np.cos(phi_rad), -np.sin(phi_rad)], axis=1)
    sense = "counter-clockwise" if spec.direction > 0 else "clockwise"
    note = (f"Format B (numpy sweep, no commands stored): {spec.description}. Commands rebuilt from PROVENANCE: "
            f"dl = -{spec.amplitude_mm:g}*[cos phi, sin phi, -cos phi, -sin phi], "
            f"phi = {'+' if spec.direction > 0 else '-'}2*pi*(column mod {spec.steps})/{spec.steps} ({sense}); "
            f"tendon_k = -dl_k.")
    return _Poses(index=index, tendon_mm=-dl_mm + 0.0, tip_mm=xyz_mm, rejected=tuple(int(i) for i in index[~plausible]),
                  dropped=(), format_note=note)


def _relative_source(path: Path) -> str:
    """The file's path inside the source repository (from 'experiments/' on), else its name."""
    parts = path.resolve().parts
    return "/".join(parts[parts.index("experiments"):]) if "experiments" in parts else path.name


def _write_log(source: Path, poses: _Poses, out_csv: Path, overwrite: bool) -> Path:
    relative = _relative_source(source)
    commit = _SOURCE_COMMITS.get(source.name)
    origin = f"{REPOSITORY}@{commit}:{relative}" if commit else f"{REPOSITORY}:{relative}"
    notes = [
        f"Real measurements imported from {origin} (single-segment 4-cable continuum robot, NDI Aurora tip "
        "tracker); see PROVENANCE.md beside the data. All rights reserved by its authors: local validation only.",
        poses.format_note,
        "Static poses, each sampled after a wait and not at a fixed rate: t = source index * 1.0 s and "
        "sample_rate_hz = 1.0 only order the poses; they are not time.",
        "Source dl > 0 pays a cable out: crest tendon_k = -dl_k (positive = pulled). The dl are open-loop servo "
        "commands: tendon_pos = tendon_cmd (no measured positions).",
        f"Insertion fixed: one {INSERTION_MM:g} mm segment, insertion_cmd = insertion_pos = {INSERTION_MM:g} mm.",
        "Tip: Aurora tip position in the model frame (origin at the robot base, z along the unbent backbone, "
        "x toward cable 1), used as the crest base frame; orientation rx, ry, rz not imported.",
        f"catheter.tendon_offset_mm = {CATHETER['tendon_offset_mm']:g} is an estimate (12 mm of cable gives about "
        "90 deg); the source code says 8 mm or 4 mm: calibrate it. outer_diameter_mm is unknown (null).",
    ]
    if poses.rejected:
        notes.append(f"Tracker samples rejected as missing (non-finite or beyond {MAX_PLAUSIBLE_TIP_MM:g} mm), "
                     f"source index: {', '.join(map(str, poses.rejected))}.")
    if poses.dropped:
        notes.append("Placeholder rows without a measurement (all-zero pose) dropped, source index: "
                     f"{', '.join(map(str, poses.dropped))}.")

    with LogWriter(out_csv, catheter=CATHETER, sample_rate_hz=1.0 / SAMPLE_PERIOD_S, source=origin,
                   notes="\n".join(notes), overwrite=overwrite) as writer:
        for index, tendon_mm, tip_mm in zip(poses.index, poses.tendon_mm, poses.tip_mm):
            writer.write(float(index) * SAMPLE_PERIOD_S, tendon_mm, INSERTION_MM, tendon_mm, INSERTION_MM, tip_mm)
        summary = {"import": {"original": relative, "repository": REPOSITORY, "commit": commit,
                              "rejected_tip_index": list(poses.rejected), "dropped_index": list(poses.dropped)}}
        writer.close(summary)
    return writer.path
