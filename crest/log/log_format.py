"""The crest experiment log format ``crest-log/1``: a CSV body and a JSON sidecar.

CSV body: one header line of column names, then one row per sample; every line ends in ``\\n``.
    required: t, tendon_cmd_1..tendon_cmd_4, insertion_cmd, tendon_pos_1..tendon_pos_4,
              insertion_pos, tip_x, tip_y, tip_z
    optional: tendon_force_1..tendon_force_4 (all four or none),
              tip_ref_x, tip_ref_y, tip_ref_z (all three or none)
Columns may come in any order; unknown or repeated columns are refused.

Conventions:
- Units: s (t), mm (tendon, insertion, tip), N (tendon_force).
- t is strictly increasing.
- Tendon k sits at (k-1)*90 deg, measured from +x toward +y. A positive tendon value means pulled.
- insertion is the free length extended from the tube.
- The tip is in the base frame: origin at the centre of the tube exit, z out of the tube,
  x toward tendon 1.
- A row holds only what was measured at its time; an empty cell is a value not measured then.
- A missing tracker sample is an empty cell (tip_x, tip_y, tip_z all empty). A row's tip comes
  from a tracker frame that arrived since the row before: a log written faster than the tracker
  has empty tips between frames, never the previous frame again.
- An empty position cell (tendon_pos_k or insertion_pos, each on its own) means that the drive's
  answer to this row's SYNC did not come: the row holds no position of that axis, never an
  earlier answer again. An empty tendon_pos_k goes with an empty tendon_force_k when the
  tendon_force group is present (the force comes in the same answer); a tendon_force_k cell may
  also be empty on its own (no force measured). Logs whose positions are all numbers stay valid.
- Empty cells are allowed only in the position, tip, tip_ref and tendon_force columns; t and the
  commands (tendon_cmd_k, insertion_cmd) are always finite numbers. Numbers are plain decimals
  (``nan``/``inf`` text is refused).
- The writer writes whole lines; a last line without its ``\\n`` is the partial write of a killed
  writer, and the reader drops it with a `TruncatedLogWarning`.

JSON sidecar: same stem, suffix ``.json``:
    {"format": "crest-log/1",
     "catheter": {"flexible_length_mm": >0, "outer_diameter_mm": >0 or null,
                  "tendon_offset_mm": >0, "tendon_angles_deg": [4 numbers]},
     "sample_rate_hz": >0, "source": "...", "notes": "..."}
Further keys are allowed (the writer adds ``config``, ``software``, ``created_utc``, ``columns``,
``units``, on the virtual testbed ``plant`` (what it simulated behind the drives, and whether that is
the controller's own model: in or out of family) and, at close, ``summary``). ``units`` maps each column of the header to its unit
(COLUMN_UNITS: "s", "mm" or "N"), e.g. ``{"t": "s", "tendon_cmd_1": "mm", "tendon_force_1": "N"}``;
it is optional (older logs lack it), and when present every entry must name a known column with
the unit this format fixes for it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

FORMAT_TAG = "crest-log/1"

TIME_COLUMN = "t"
TENDON_CMD_COLUMNS = ("tendon_cmd_1", "tendon_cmd_2", "tendon_cmd_3", "tendon_cmd_4")
INSERTION_CMD_COLUMN = "insertion_cmd"
TENDON_POS_COLUMNS = ("tendon_pos_1", "tendon_pos_2", "tendon_pos_3", "tendon_pos_4")
INSERTION_POS_COLUMN = "insertion_pos"
TIP_COLUMNS = ("tip_x", "tip_y", "tip_z")
TENDON_FORCE_COLUMNS = ("tendon_force_1", "tendon_force_2", "tendon_force_3", "tendon_force_4")
TIP_REF_COLUMNS = ("tip_ref_x", "tip_ref_y", "tip_ref_z")

REQUIRED_COLUMNS = ((TIME_COLUMN,) + TENDON_CMD_COLUMNS + (INSERTION_CMD_COLUMN,) + TENDON_POS_COLUMNS
                    + (INSERTION_POS_COLUMN,) + TIP_COLUMNS)
OPTIONAL_COLUMN_GROUPS = {"tendon_force": TENDON_FORCE_COLUMNS, "tip_ref": TIP_REF_COLUMNS}
# Columns that must hold a finite number on every row; the others may be empty (missing).
FINITE_COLUMNS = (TIME_COLUMN,) + TENDON_CMD_COLUMNS + (INSERTION_CMD_COLUMN,)

COLUMN_UNITS = {TIME_COLUMN: "s",
                **{name: "mm" for name in TENDON_CMD_COLUMNS + (INSERTION_CMD_COLUMN,) + TENDON_POS_COLUMNS
                   + (INSERTION_POS_COLUMN,) + TIP_COLUMNS + TIP_REF_COLUMNS},
                **{name: "N" for name in TENDON_FORCE_COLUMNS}}
"""The unit of every column this format knows (the sidecar's ``units`` lists those of its header)."""

TENDON_ANGLES_DEG = (0.0, 90.0, 180.0, 270.0)


class LogFormatError(ValueError):
    """A file that is not a valid crest log. The message names the file, and the line and column
    when the problem is in one place."""

    def __init__(self, path: Path, problem: str, *, line: int | None = None, column: str | None = None) -> None:
        self.path = path
        self.line = line
        self.column = column
        where = str(path)
        if line is not None:
            where += f", line {line}"
        if column is not None:
            where += f", column {column!r}"
        super().__init__(f"{where}: {problem}")


class TruncatedLogWarning(UserWarning):
    """The last line of a log had no newline (a killed writer) and was dropped."""


def sidecar_path(csv_path: Path | str) -> Path:
    """The JSON sidecar of a log: the CSV path with suffix ``.json``."""
    return Path(csv_path).with_suffix(".json")


def header_columns(*, tendon_force: bool = False, tip_ref: bool = False) -> tuple[str, ...]:
    """The header the writer uses: required columns, then the chosen optional groups."""
    return (REQUIRED_COLUMNS + (TENDON_FORCE_COLUMNS if tendon_force else ())
            + (TIP_REF_COLUMNS if tip_ref else ()))


def check_header(columns: list[str], path: Path) -> None:
    """Refuse missing, unknown, repeated columns and incomplete optional groups (header is line 1)."""
    known = set(REQUIRED_COLUMNS + TENDON_FORCE_COLUMNS + TIP_REF_COLUMNS)
    seen: set[str] = set()
    for name in columns:
        if name not in known:
            raise LogFormatError(path, f"unknown column; a {FORMAT_TAG} header holds only "
                                       f"{', '.join(REQUIRED_COLUMNS)} and optional groups "
                                       f"{', '.join(TENDON_FORCE_COLUMNS + TIP_REF_COLUMNS)}", line=1, column=name)
        if name in seen:
            raise LogFormatError(path, "column appears twice in the header", line=1, column=name)
        seen.add(name)
    missing = [name for name in REQUIRED_COLUMNS if name not in seen]
    if missing:
        raise LogFormatError(path, f"missing required column(s) {', '.join(missing)}", line=1)
    for group, names in OPTIONAL_COLUMN_GROUPS.items():
        present = [name for name in names if name in seen]
        if present and len(present) != len(names):
            raise LogFormatError(path, f"optional group {group} needs all of {', '.join(names)}; "
                                       f"only {', '.join(present)} present", line=1)


def check_sidecar(sidecar: Any, path: Path) -> dict[str, Any]:
    """Validate a parsed sidecar against crest-log/1 and return it; ``path`` is the JSON file."""
    if not isinstance(sidecar, dict):
        raise LogFormatError(path, f"the sidecar must be a JSON object, got {type(sidecar).__name__}")
    tag = sidecar.get("format")
    if tag != FORMAT_TAG:
        raise LogFormatError(path, f"format is {tag!r}; expected {FORMAT_TAG!r}")
    for key, kind in (("catheter", dict), ("source", str), ("notes", str)):
        if not isinstance(sidecar.get(key), kind):
            raise LogFormatError(path, f"{key!r} must be a JSON {'object' if kind is dict else 'string'}, "
                                       f"got {sidecar.get(key)!r}")
    _check_positive(sidecar.get("sample_rate_hz"), path, "sample_rate_hz")
    catheter = sidecar["catheter"]
    _check_positive(catheter.get("flexible_length_mm"), path, "catheter.flexible_length_mm")
    _check_positive(catheter.get("tendon_offset_mm"), path, "catheter.tendon_offset_mm")
    if "outer_diameter_mm" not in catheter:
        raise LogFormatError(path, "catheter.outer_diameter_mm is missing; give it in mm or null when unknown")
    if catheter["outer_diameter_mm"] is not None:
        _check_positive(catheter["outer_diameter_mm"], path, "catheter.outer_diameter_mm")
    if "units" in sidecar:
        _check_units(sidecar["units"], path)
    if "plant" in sidecar and not isinstance(sidecar["plant"], str):
        raise LogFormatError(path, f"'plant' must be a JSON string (the virtual testbed's plant), got {sidecar['plant']!r}")
    angles = catheter.get("tendon_angles_deg")
    if (not isinstance(angles, list) or len(angles) != 4
            or not all(_is_number(angle) and math.isfinite(angle) for angle in angles)):
        raise LogFormatError(path, f"catheter.tendon_angles_deg must be a list of 4 numbers such as "
                                   f"[0, 90, 180, 270], got {angles!r}")
    return sidecar


def units_of(columns: Sequence[str]) -> dict[str, str]:
    """The sidecar's ``units``: each column's unit, in header order."""
    return {name: COLUMN_UNITS[name] for name in columns}


def _check_units(units: Any, path: Path) -> None:
    """Refuse a ``units`` entry that is not a known column with this format's unit for it."""
    if not isinstance(units, dict):
        raise LogFormatError(path, f"'units' must be a JSON object mapping columns to units, got {units!r}")
    for name, unit in units.items():
        if name not in COLUMN_UNITS:
            raise LogFormatError(path, f"units names {name!r}, which is not a {FORMAT_TAG} column")
        if unit != COLUMN_UNITS[name]:
            raise LogFormatError(path, f"units.{name} is {unit!r}, but {FORMAT_TAG} stores {name} in "
                                       f"{COLUMN_UNITS[name]!r}: convert the column and write "
                                       f"{COLUMN_UNITS[name]!r}")


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _check_positive(value: Any, path: Path, field: str) -> None:
    if not (_is_number(value) and math.isfinite(value) and value > 0):
        raise LogFormatError(path, f"{field} must be a finite number > 0, got {value!r}")


def catheter_dict(*, flexible_length_mm: float, tendon_offset_mm: float, outer_diameter_mm: float | None,
                  tendon_angles_deg: Sequence[float] = TENDON_ANGLES_DEG) -> dict[str, Any]:
    """The sidecar's ``catheter`` object from its four values (angles default to 0, 90, 180, 270)."""
    return {"flexible_length_mm": float(flexible_length_mm),
            "outer_diameter_mm": None if outer_diameter_mm is None else float(outer_diameter_mm),
            "tendon_offset_mm": float(tendon_offset_mm),
            "tendon_angles_deg": [float(angle) for angle in tendon_angles_deg]}
