"""The drive tensions a run along a path reports are those a sample-by-sample run leaves (what the drives log)."""
import numpy as np
import pytest

from model import DahlCatheter
from model.effects import combined_terms
from tests.model.conftest import articulation


@pytest.mark.parametrize("dynamic", [False, True])
def test_run_with_tension_reports_each_samples_drive_tension(params, dynamic):
    if dynamic:
        params = params.replace(damping_time_s=0.02, inertia_scale=1.0)
    effects = combined_terms({"rate_friction": (0.05,), "backlash": (0.2,)})
    bend = np.linspace(0.0, 1.0, 40)[:, None] * articulation(params, 150.0, 30.0, pretension_mm=0.5)
    path = np.vstack([bend, bend[::-1]])
    insertion = np.linspace(params.free_length_mm, params.free_length_mm - 5.0, len(path))
    whole = DahlCatheter(params, 8, effects)
    tips, tension = whole.run_with_tension(path, insertion, 0.02)
    stepped = DahlCatheter(params, 8, effects)
    for t in range(len(path)):
        assert stepped.run(path[t:t + 1], insertion[t:t + 1], 0.02)[0] == pytest.approx(tips[t], abs=1e-12)
        assert stepped.drive_tension_n == pytest.approx(tension[t], abs=1e-12)
    assert tension.max() > 1.0      # the tendons carried load
