"""Rate friction (effect `rate_friction`): Fs*(1 + c*|v|) with v the tendon's pull speed."""
import numpy as np

from model import DahlCatheter, EffectTerms
from tests.model.conftest import articulation, tip_angle_rad

RATE_S_PER_MM = 0.3


def loop(params, period_s: float, rate_hz: float, rate_s_per_mm: float = RATE_S_PER_MM) -> np.ndarray:
    """Tip angles over one 0 -> 120 -> 0 deg articulation cycle taking period_s, sampled at rate_hz."""
    n = int(period_s * rate_hz)
    degrees = 120.0 * np.sin(np.linspace(0.0, np.pi, n + 1)) ** 2
    tendons = np.array([articulation(params, d) for d in degrees])
    model = DahlCatheter(params, effects=EffectTerms(rate_friction_s_per_mm=rate_s_per_mm))
    return tip_angle_rad(model.run(tendons, dt_s=1.0 / rate_hz))


def loop_width_rad(angles: np.ndarray) -> float:
    """Largest gap between the loading and the unloading branch at the same input (the input
    path is symmetric in time: sample i and sample n-1-i have the same input)."""
    half = len(angles) // 2
    return float(np.max(np.abs(angles[:half] - angles[::-1][:half])))


def test_loop_widens_with_speed(params):
    slow, fast = loop_width_rad(loop(params, 40.0, 100.0)), loop_width_rad(loop(params, 2.0, 100.0))
    assert fast > 1.3 * slow


def test_without_rate_friction_speed_does_not_matter(params):
    slow, fast = loop(params, 40.0, 100.0, 0.0), loop(params, 2.0, 100.0, 0.0)
    assert abs(loop_width_rad(fast) - loop_width_rad(slow)) < 0.01 * loop_width_rad(slow)


def test_tip_does_not_depend_on_the_sample_rate(params):
    """The plant steps at the SYNC rate, a diagnosis at 10 Hz: the same motion must give the same tips."""
    fine, coarse = loop(params, 4.0, 1000.0), loop(params, 4.0, 20.0)
    assert np.max(np.abs(fine[::50] - coarse)) < np.deg2rad(0.5)


def test_tip_is_continuous_at_reversals_when_sampled_finely(params):
    angles = loop(params, 4.0, 1000.0)
    assert np.max(np.abs(np.diff(angles))) < np.deg2rad(0.5)
