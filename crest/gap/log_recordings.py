"""Turn crest-log/1 experiment logs into the arrays the gap analysis works on."""
from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from crest.log import ExperimentLog, read_log
from crest.log.missing_positions import filled_positions_mm
from model.gap.recording import Recording, RecordingError

MODEL_TENDON_ANGLES_DEG = (0.0, 90.0, 180.0, 270.0)


def recording_from_log(log: ExperimentLog) -> Recording:
    """The log's measured positions, tips, forces and catheter geometry as a Recording.

    The positions drive the model, so an axis' empty position cells (its drive did not answer
    that SYNC) are filled from its measured rows (`filled_positions_mm`); an axis with no measured
    row is refused (LogFormatError). Forces stay NaN where the log has none.
    The model's tendons sit at 0, 90, 180, 270 deg; a log with other tendon angles is refused.
    A row whose tip repeats the previous row's exactly holds the tracker's last frame (the log
    runs at the SYNC rate, the tracker slower): it is not a measurement and counts as missing.
    """
    angles = np.mod(np.asarray(log.catheter["tendon_angles_deg"], dtype=float), 360.0)
    if not np.allclose(angles, MODEL_TENDON_ANGLES_DEG, atol=1e-6):
        raise RecordingError(f"{log.path}: catheter.tendon_angles_deg is {log.catheter['tendon_angles_deg']}; "
                             f"the model needs tendons at {list(MODEL_TENDON_ANGLES_DEG)} (reorder the tendon "
                             "columns when importing)")
    tip = np.array(log.tip_mm, dtype=float)
    tip[1:][np.all(tip[1:] == tip[:-1], axis=1)] = np.nan
    tendon_mm, insertion_mm = filled_positions_mm(log)
    return Recording(name=Path(log.path).name, t_s=np.asarray(log.t_s), tendon_mm=tendon_mm,
                     insertion_mm=insertion_mm, tip_mm=tip,
                     tendon_force_n=None if log.tendon_force_n is None else np.asarray(log.tendon_force_n),
                     flexible_length_mm=float(log.catheter["flexible_length_mm"]),
                     tendon_offset_mm=float(log.catheter["tendon_offset_mm"]),
                     outer_diameter_mm=log.catheter["outer_diameter_mm"])


def load_recordings(paths: Sequence[Path | str]) -> list[Recording]:
    """Read and convert each log (LogFormatError / RecordingError name the file)."""
    return [recording_from_log(read_log(path)) for path in paths]
