"""Model inputs from a log's positions: each axis' empty cells filled from its measured rows.

In ``crest-log/1`` an empty position cell (tendon_pos_k, insertion_pos) is a drive whose answer to
that row's SYNC did not come (log_format). A model input cannot be missing, so a consumer that
drives a model (or draws one) with the positions fills them here, axis by axis: at a row time t
between that axis' nearest measured rows (t0, p0) before and (t1, p1) after,

    p(t) = p0 + (p1 - p0) * (t - t0) / (t1 - t0),

and before the axis' first or after its last measured row, the nearest measured value (p of the
first or last). Rows that were measured keep their value exactly. The filled values are inputs
for the consumer only: they are never written back into a log, which keeps its empty cells.
"""
from __future__ import annotations

import numpy as np

from crest.log.log_format import INSERTION_POS_COLUMN, TENDON_POS_COLUMNS, LogFormatError
from crest.log.log_reader import ExperimentLog


def filled_positions_mm(log: ExperimentLog) -> tuple[np.ndarray, np.ndarray]:
    """(tendon_pos_mm [T, 4], insertion_pos_mm [T]) of the log in mm, each axis filled as the
    module docstring says; new arrays, the log is unchanged.

    Raises LogFormatError naming the file and the column when an axis has no measured position on
    any row (nothing to fill from). A log without rows gives empty arrays.
    """
    tendon_mm = np.column_stack([_filled(log, log.tendon_pos_mm[:, k], column)
                                 for k, column in enumerate(TENDON_POS_COLUMNS)]).reshape(len(log), 4)
    return tendon_mm, _filled(log, log.insertion_pos_mm, INSERTION_POS_COLUMN)


def _filled(log: ExperimentLog, position_mm: np.ndarray, column: str) -> np.ndarray:
    """One axis' positions [T] with its empty cells (NaN) interpolated in time (module docstring)."""
    measured = ~np.isnan(position_mm)
    if measured.all():
        return np.array(position_mm, dtype=float)
    if not measured.any():
        raise LogFormatError(log.path, f"no row holds a measured position (every {column} cell is empty: the "
                                       "drive never answered), so this axis cannot drive the model; record the "
                                       "run again with that drive answering", column=column)
    filled = np.array(position_mm, dtype=float)
    filled[~measured] = np.interp(log.t_s[~measured], log.t_s[measured], position_mm[measured])
    return filled
