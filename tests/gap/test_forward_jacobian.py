"""The fits' finite differences step far above the kernel's solver noise, also where a parameter
starts at exactly 0 (an effect switched off, a tendon zero, a log-scaled parameter at its reference)."""
import numpy as np
from scipy.optimize import least_squares

from model.gap.calibration import DIFF_STEP, forward_jacobian


def residuals_with_solver_noise(z: np.ndarray) -> np.ndarray:
    """A straight line in z[0] (slope 1, zero at 0.3) plus a 1e-6 wobble on the scale of 1e-8, as
    a Newton solve that stops at its tolerance adds."""
    return np.array([z[0] - 0.3 + 1e-6 * np.sin(3e8 * z[0]), z[1]])


def test_a_parameter_at_zero_gets_a_step_of_diff_step_not_scipys_fallback():
    low, high = np.array([-5.0, -5.0]), np.array([5.0, 5.0])
    jacobian = forward_jacobian(residuals_with_solver_noise, residuals_with_solver_noise, np.zeros(2), low, high)
    assert abs(jacobian[0, 0] - 1.0) < 1e-3
    scipy_at_zero = least_squares(residuals_with_solver_noise, np.zeros(2), diff_step=DIFF_STEP, max_nfev=1).jac
    assert abs(scipy_at_zero[0, 0] - 1.0) > 1.0      # scipy's 1.5e-8 step at 0 sees the wobble


def test_the_step_turns_back_at_an_upper_bound():
    low, high = np.array([-1.0, -1.0]), np.array([0.01, 5.0])
    jacobian = forward_jacobian(residuals_with_solver_noise, residuals_with_solver_noise, np.zeros(2), low, high)
    assert abs(jacobian[0, 0] - 1.0) < 1e-3 and jacobian[1, 1] == 1.0
