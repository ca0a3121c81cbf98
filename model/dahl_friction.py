"""The modified Dahl friction element (seed paper II.B, equations 1-3).

One element sits at every place a tendon crosses a lumped catheter element. Its state is
the friction force F [N] that it adds to the tendon tension going toward the base; x [mm]
is the sliding of the tendon relative to the lumen, positive toward the base (tendon pulled).
"""
import math

from model.jit import kernel


@kernel
def capstan_gain(mu: float, theta_rad: float) -> float:
    """dFs/dT_avg: the capstan part of the steady-state friction, Fs = Fsc + gain * T_avg.

    A tendon sliding over a curve that subtends theta with friction coefficient mu obeys
    T_left / T_right = e^(mu*theta) (paper eq. 2). With T_avg = (T_left + T_right)/2 the
    difference is (paper eq. 3)

        Fsv = T_left - T_right = 2*T_avg*(e^(mu*theta) - 1)/(e^(mu*theta) + 1) = 2*T_avg*tanh(mu*theta/2)

    A slack (negative) tension carries no normal force: callers clip T_avg at 0.
    """
    return 2.0 * math.tanh(0.5 * mu * abs(theta_rad))


@kernel
def dahl_slope(force_n: float, fs_n: float, sigma_n_per_mm: float, alpha: float, direction: float) -> float:
    """dF/dx = sigma * (1 - F/Fs * sgn(v))^alpha  (paper eq. 1), clipped at 0 beyond Fs."""
    if fs_n <= 0.0:
        return 0.0
    base = 1.0 - force_n / fs_n * direction
    if base <= 0.0:
        return 0.0
    return sigma_n_per_mm * (base if alpha == 1.0 else base ** alpha)


@kernel
def dahl_update_with_slopes(force_n: float, dx_mm: float, fs_n: float, sigma_n_per_mm: float,
                            alpha: float) -> tuple:
    """dahl_update (below, which states the law) and its derivatives (F, dF/d(dx), dF/dFs).

    With z the value after the step and z0 before it (see dahl_update):

        dF/d(dx) = sigma * z^alpha
        dF/dFs   = d*(1 - z) - d*z^alpha*(d*F0/(z0^alpha*Fs) + sigma*|dx|/Fs)

    At dx = 0 the force does not change, so dF/dFs = 0, and dF/d(dx) is the mean of the two
    one-sided slopes; in saturated sliding (z -> 0) F = d*Fs and dF/dFs = d. Where |F| is
    clipped to Fs, dF/dFs = sgn(F).
    """
    if fs_n <= 0.0:
        return 0.0, 0.0, 0.0
    if dx_mm == 0.0:
        if abs(force_n) >= fs_n:
            return (fs_n if force_n > 0.0 else -fs_n), 0.0, (1.0 if force_n > 0.0 else -1.0)
        mean_slope = 0.5 * (dahl_slope(force_n, fs_n, sigma_n_per_mm, alpha, 1.0)
                            + dahl_slope(force_n, fs_n, sigma_n_per_mm, alpha, -1.0))
        return force_n, mean_slope, 0.0
    direction = 1.0 if dx_mm > 0.0 else -1.0
    z0 = 1.0 - direction * force_n / fs_n
    if z0 <= 0.0:
        return direction * fs_n, 0.0, direction
    decay = sigma_n_per_mm * abs(dx_mm) / fs_n
    if alpha == 1.0:
        z = z0 * math.exp(-decay) if decay < 40.0 else 0.0   # e^-40 ~ 4e-18: saturated
    elif alpha < 1.0:
        w = z0 ** (1.0 - alpha) - (1.0 - alpha) * decay
        z = w ** (1.0 / (1.0 - alpha)) if w > 0.0 else 0.0
    else:
        z = (z0 ** (1.0 - alpha) + (alpha - 1.0) * decay) ** (-1.0 / (alpha - 1.0))
    force = direction * fs_n * (1.0 - z)
    if force > fs_n or force < -fs_n:
        sign = 1.0 if force > 0.0 else -1.0
        return sign * fs_n, 0.0, sign
    za = z if alpha == 1.0 else z ** alpha
    z0a = z0 if alpha == 1.0 else z0 ** alpha
    d_dx = sigma_n_per_mm * za
    d_fs = direction * (1.0 - z) - direction * za * (direction * force_n / (z0a * fs_n) + decay)
    return force, d_dx, d_fs


@kernel
def dahl_update(force_n: float, dx_mm: float, fs_n: float, sigma_n_per_mm: float, alpha: float) -> float:
    """Integrate paper eq. 1 exactly over a sliding increment dx [mm].

    With d = sgn(dx) and z = 1 - d*F/Fs, eq. 1 becomes dz/d|x| = -(sigma/Fs) z^alpha, so

        alpha = 1:  z = z0 * exp(-sigma*|dx|/Fs)
        alpha != 1: z^(1-alpha) = z0^(1-alpha) - (1-alpha)*sigma*|dx|/Fs     (z >= 0)

    and F = d*Fs*(1 - z). The update is exact for any step size, so the element never
    overshoots Fs. |F| is kept within Fs (Fs varies with tension, the "modified" Dahl model).
    """
    return dahl_update_with_slopes(force_n, dx_mm, fs_n, sigma_n_per_mm, alpha)[0]
