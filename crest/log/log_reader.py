"""Read a crest-log/1 experiment log (CSV + JSON sidecar, see log_format) into numpy arrays."""

from __future__ import annotations

import json
import math
import re
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from crest.log.log_format import (
    FINITE_COLUMNS,
    INSERTION_CMD_COLUMN,
    INSERTION_POS_COLUMN,
    TENDON_CMD_COLUMNS,
    TENDON_FORCE_COLUMNS,
    TENDON_POS_COLUMNS,
    TIME_COLUMN,
    TIP_COLUMNS,
    TIP_REF_COLUMNS,
    LogFormatError,
    TruncatedLogWarning,
    check_header,
    check_sidecar,
    sidecar_path,
)

# A plain decimal number: what the writer and common CSV tools produce. Refuses nan/inf text,
# digit separators and padding, which Python's float() would accept.
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


@dataclass(frozen=True)
class ExperimentLog:
    """One experiment log as read-only arrays over T samples (units: s, mm, N).

    ``tip_mm`` is NaN on rows where the tracker sample is missing; ``tendon_pos_mm`` and
    ``insertion_pos_mm`` are NaN where that axis' drive did not answer the row's SYNC (an empty
    cell; `missing_positions.filled_positions_mm` gives model inputs without gaps);
    ``tendon_force_n`` and ``tip_ref_mm`` are None when the log has no such columns (NaN where a
    cell is empty). t and the commands are finite on every row.
    ``sidecar`` is the whole JSON sidecar (units per column, config snapshot, software version,
    summary, ...).
    """

    path: Path
    t_s: np.ndarray
    tendon_cmd_mm: np.ndarray
    insertion_cmd_mm: np.ndarray
    tendon_pos_mm: np.ndarray
    insertion_pos_mm: np.ndarray
    tip_mm: np.ndarray
    tendon_force_n: np.ndarray | None
    tip_ref_mm: np.ndarray | None
    catheter: dict[str, Any]
    sample_rate_hz: float
    source: str
    notes: str
    sidecar: dict[str, Any]

    def __len__(self) -> int:
        return len(self.t_s)

    @property
    def plant(self) -> str | None:
        """What the virtual testbed simulated behind the drives, with its family (None: a log of hardware,
        imported, or written before crest kept it)."""
        return self.sidecar.get("plant")

    @property
    def tip_valid(self) -> np.ndarray:
        """Boolean mask [T] of rows with a tracker sample."""
        return np.all(np.isfinite(self.tip_mm), axis=1)


def recorded_plant(csv_path: Path | str) -> str | None:
    """`ExperimentLog.plant` from the log's sidecar alone (the rows are not read)."""
    return _read_sidecar(_existing_log(csv_path)).get("plant")


def read_log(csv_path: Path | str) -> ExperimentLog:
    """Read and validate a log and its sidecar; LogFormatError names file, line and column.

    A last line without its newline (a killed writer) is dropped with a TruncatedLogWarning.
    """
    path = _existing_log(csv_path)
    sidecar = _read_sidecar(path)
    columns, rows = _read_rows(path)
    by_name = {name: position for position, name in enumerate(columns)}
    table = np.array(rows, dtype=float).reshape(len(rows), len(columns))

    def block(names: tuple[str, ...]) -> np.ndarray:
        return _read_only(table[:, [by_name[name] for name in names]])

    def optional_block(names: tuple[str, ...]) -> np.ndarray | None:
        return block(names) if names[0] in by_name else None

    return ExperimentLog(
        path=path,
        t_s=_read_only(table[:, by_name[TIME_COLUMN]]),
        tendon_cmd_mm=block(TENDON_CMD_COLUMNS),
        insertion_cmd_mm=_read_only(table[:, by_name[INSERTION_CMD_COLUMN]]),
        tendon_pos_mm=block(TENDON_POS_COLUMNS),
        insertion_pos_mm=_read_only(table[:, by_name[INSERTION_POS_COLUMN]]),
        tip_mm=block(TIP_COLUMNS),
        tendon_force_n=optional_block(TENDON_FORCE_COLUMNS),
        tip_ref_mm=optional_block(TIP_REF_COLUMNS),
        catheter=sidecar["catheter"],
        sample_rate_hz=float(sidecar["sample_rate_hz"]),
        source=sidecar["source"],
        notes=sidecar["notes"],
        sidecar=sidecar,
    )


def _read_only(array: np.ndarray) -> np.ndarray:
    array = np.ascontiguousarray(array)
    array.flags.writeable = False
    return array


def _refuse_constant(name: str) -> None:
    raise ValueError(f"{name} is not valid JSON; write null for a missing value")


def _existing_log(csv_path: Path | str) -> Path:
    path = Path(csv_path)
    if not path.is_file():
        raise LogFormatError(path, "no such file" if not path.exists() else "not a file (a crest log is a .csv file)")
    return path


def _read_sidecar(csv_path: Path) -> dict[str, Any]:
    path = sidecar_path(csv_path)
    try:
        text = path.read_bytes().decode("utf-8")
    except FileNotFoundError as error:
        raise LogFormatError(path, f"the sidecar of {csv_path.name} is missing; every crest log needs "
                                   f"{path.name} beside it (see log_format)") from error
    except OSError as error:
        raise LogFormatError(path, f"cannot read the sidecar ({error.strerror or error})") from error
    except UnicodeDecodeError as error:
        raise LogFormatError(path, f"not UTF-8 text (byte {error.start})") from error
    try:
        sidecar = json.loads(text, parse_constant=_refuse_constant)
    except json.JSONDecodeError as error:
        raise LogFormatError(path, f"invalid JSON: {error.msg} (column {error.colno})", line=error.lineno) from error
    except (ValueError, RecursionError) as error:
        raise LogFormatError(path, f"invalid JSON: {error}") from error
    return check_sidecar(sidecar, path)


def _read_rows(path: Path) -> tuple[list[str], list[list[float]]]:
    """Header and numeric rows (NaN for empty cells), every cell checked against the format."""
    try:
        data = path.read_bytes()
    except OSError as error:
        raise LogFormatError(path, f"cannot read the log ({error.strerror or error})") from error
    lines = data.split(b"\n")
    if lines[-1]:
        if len(lines) > 1:
            warnings.warn(f"{path}, line {len(lines)}: the last line has no newline (the writer was killed "
                          "mid-write); it is dropped", TruncatedLogWarning, stacklevel=3)
        else:
            raise LogFormatError(path, "the header line is incomplete (no newline); the log has no data", line=1)
    lines = lines[:-1]
    if not lines:
        raise LogFormatError(path, "empty file; a crest log starts with a header line", line=1)

    columns = _decode(lines[0], path, 1).split(",")
    check_header(columns, path)
    finite_positions = [columns.index(name) for name in FINITE_COLUMNS]
    groups = [[columns.index(name) for name in names]
              for names in (TIP_COLUMNS, TIP_REF_COLUMNS) if names[0] in columns]
    # (tendon_pos_k, tendon_force_k): both come in one drive answer, so an empty position needs an empty force.
    answers = ([(columns.index(pos), columns.index(force))
                for pos, force in zip(TENDON_POS_COLUMNS, TENDON_FORCE_COLUMNS)]
               if TENDON_FORCE_COLUMNS[0] in columns else [])

    rows = []
    previous_t_s = -math.inf
    time_position = columns.index(TIME_COLUMN)
    for number, raw in enumerate(lines[1:], start=2):
        cells = _decode(raw, path, number).split(",")
        if len(cells) != len(columns):
            raise LogFormatError(path, f"expected {len(columns)} cells, got {len(cells)}", line=number)
        values = []
        for cell, name in zip(cells, columns):
            if cell == "":
                values.append(math.nan)
            elif _NUMBER.fullmatch(cell) and math.isfinite(float(cell)):
                values.append(float(cell))
            else:
                raise LogFormatError(path, f"not a finite number: {cell[:40]!r} (a missing sample is an empty cell)",
                                     line=number, column=name)
        for position in finite_positions:
            if not math.isfinite(values[position]):
                raise LogFormatError(path, "empty; this column must hold a number on every row (only position, "
                                           "tip, tip_ref and tendon_force cells may be empty)", line=number,
                                     column=columns[position])
        for position, force in answers:
            if math.isnan(values[position]) and not math.isnan(values[force]):
                raise LogFormatError(path, f"{columns[position]} is empty (the drive's answer to this SYNC did not "
                                           f"come) but {columns[force]} holds a number; leave both empty",
                                     line=number, column=columns[force])
        for positions in groups:
            missing = [math.isnan(values[position]) for position in positions]
            if any(missing) and not all(missing):
                raise LogFormatError(path, f"{', '.join(columns[p] for p in positions)} must be all present "
                                           "or all empty", line=number, column=columns[positions[missing.index(True)]])
        t_s = values[time_position]
        if not t_s > previous_t_s:
            raise LogFormatError(path, f"t must increase strictly; {t_s!r} follows {previous_t_s!r}",
                                 line=number, column=TIME_COLUMN)
        previous_t_s = t_s
        rows.append(values)
    return columns, rows


def _decode(raw: bytes, path: Path, line: int) -> str:
    try:
        return raw.decode("ascii").removesuffix("\r")
    except UnicodeDecodeError as error:
        raise LogFormatError(path, f"non-ASCII byte at position {error.start + 1}; the log is plain ASCII CSV",
                             line=line) from error
