"""Set-point files for `crest run FILE.csv`: tendon and insertion set-points over time.

Columns: t (s), tendon_cmd_1..tendon_cmd_4 (mm, positive = pulled) and insertion_cmd (mm, free
length), the same names as in a crest log, so a recorded log replays as it is. Times must
increase; the set-points are resampled to the SYNC period by linear interpolation.
"""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from crest.driver import AxisTargets

COLUMNS = ("t", "tendon_cmd_1", "tendon_cmd_2", "tendon_cmd_3", "tendon_cmd_4", "insertion_cmd")


class SetpointFileError(ValueError):
    """The set-point file cannot be used; the message names the file, line and column."""


def read_setpoints(path: Path | str, period_s: float) -> list[AxisTargets]:
    path = Path(path)
    try:
        with path.open(newline="") as handle:
            reader = csv.DictReader(handle)
            missing = [c for c in COLUMNS if c not in (reader.fieldnames or [])]
            if missing:
                raise SetpointFileError(f"{path}: missing column(s) {', '.join(missing)}; "
                                        f"a set-point file needs {', '.join(COLUMNS)}")
            rows = []
            for row in reader:
                line = reader.line_num
                if None in row:
                    raise SetpointFileError(f"{path}, line {line}: {len(reader.fieldnames) + len(row[None])} cells, "
                                            f"but the header names {len(reader.fieldnames)} columns")
                values = []
                for column in COLUMNS:
                    if row[column] is None:
                        cells = sum(value is not None for value in row.values())
                        raise SetpointFileError(f"{path}, line {line}, column {column!r}: the row ends before this "
                                                f"column ({cells} cells, the header names {len(reader.fieldnames)})")
                    try:
                        value = float(row[column])
                    except (TypeError, ValueError):
                        raise SetpointFileError(f"{path}, line {line}, column {column!r}: "
                                                f"{row[column]!r} is not a number") from None
                    if not np.isfinite(value):
                        raise SetpointFileError(f"{path}, line {line}, column {column!r}: {value} is not finite")
                    values.append(value)
                rows.append(values)
    except OSError as exc:
        raise SetpointFileError(f"{path}: cannot read the set-point file: {exc}") from exc
    except UnicodeDecodeError as exc:
        raise SetpointFileError(f"{path}: not a text CSV file ({exc})") from exc
    if len(rows) < 2:
        raise SetpointFileError(f"{path}: needs at least two set-points")
    table = np.array(rows)
    t = table[:, 0]
    if np.any(np.diff(t) <= 0):
        line = int(np.argmax(np.diff(t) <= 0)) + 3
        raise SetpointFileError(f"{path}, line {line}: time must strictly increase")
    grid = np.arange(t[0], t[-1] + 1e-9, period_s)
    resampled = np.column_stack([np.interp(grid, t, table[:, j]) for j in range(1, len(COLUMNS))])
    return [AxisTargets(tuple(row[:4]), row[4]) for row in resampled]
