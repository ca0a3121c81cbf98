"""One quasi-static step of the rod plant: the four drive tensions that make the tendons fit.

Unknowns: the tension T_k(0) of each tendon where it enters the free length (= at its drive).
Given them, one walk from the base to the tip gives everything else:

1. Tendon tensions node by node, by the friction return mapping (tendon_friction.py) from the
   previous step's profile T_prev (the memory).
2. Curvature at each node from the moment balance of the distal part (Kirchhoff rod, tendons
   routed parallel to the backbone at moment arm a_k, angle phi_k(s) in the cross-section):

       kappa(s) = kappa_rest(s) + ( sum_k T_k(s) a_k(s) (-sin phi_k, cos phi_k) + m_w(s) ) / EI(s)

   The arm is the lumen radius r(s), less what the tendon's own load pushes its lumen toward the
   neutral axis where the lumen wall yields (radial compliance c_r(s), mm/N; lumen_compression):

       a_k = r^2 / (r + c_r T_k),   so   d(T_k a_k)/dT_k = a_k^2 / r,   d a_k/dT_k = -c_r a_k^2 / r^2

   m_w: the moment of the rod's own weight (backbone.weight_moments_body), from the latest shape.
3. The backbone, segment by segment as exact arcs (backbone.py), with axial strain
   eps(s) = -sum_k T_k(s) / EA_axial(s) (the tendons compress the shaft).

Compatibility of each tendon: the drive's pull u_k (after the drive train) is taken up by the
drive line's stretch, the tendon's stretch inside the catheter, the lumen's shortening by the
bend (relative to the shape at which the tendons were zeroed, kappa_set) and by the shaft's
compression:

    g_k = c_d T_k(0) + int_0^L [ delta_k + T_k / EA_t - eps ] ds - u_k = 0,
    delta_k(s) = a_k(s) * ( (ky - ky_set) cos phi_k - (kx - kx_set) sin phi_k )

A tendon cannot push: T_k(0) >= 0, and a tendon whose g_k >= 0 at zero tension is slack.
Solved by projected Newton on T(0) with the Jacobian of the walk (tensions' sensitivities
S_j(s) = dT_j(s)/dT_j(0), zero where the tendon sticks):

    dg_k/dT_j(0) = c_d [k=j] + int S_j(s) [ a_k a_j^2 / r cos(phi_k - phi_j) / EI + 1/EA_axial
                                            + [k=j] (1/EA_t + (d a_k/dT_k) delta_k / a_k) ] ds

The sensitivities S_j neglect how T_j's pull changes the other tendons' wraps (through the
curvature), so this Jacobian is approximate (columns off by up to a quarter on a bent rod); the
backtracking below makes up for it. The weight moment is refreshed from the latest shape at each
iteration, so the Newton loop is also the fixed point of the weight's moment. Integrals use the
trapezoid rule on the nodes.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from sim_backend.plant.rod.backbone import segment_displacement, segment_rotation, weight_moments_body
from sim_backend.plant.rod.tendon_friction import clamp_to_capstan

BACKTRACKS = 8       # halvings of a Newton step before it is taken whole


@njit(cache=True)
def _arm(r_mm, give_mm_per_n, tension_n):
    """Moment arm a = r^2 / (r + c_r T) of a tendon at tension T whose lumen wall yields by c_r per N."""
    if give_mm_per_n == 0.0:
        return r_mm
    return r_mm * r_mm / (r_mm + give_mm_per_n * tension_n)


@njit(cache=True)
def _moment_slope(r_mm, give_mm_per_n, arm_mm):
    """d(T a)/dT = a^2 / r, the moment arm a tendon's own extra tension acts through (r without give)."""
    if give_mm_per_n == 0.0:
        return r_mm
    return arm_mm * arm_mm / r_mm


@njit(cache=True)
def _curvature(i, tension, arm, cos_phi, sin_phi, ei_nmm2, kappa_rest, moment_w, out):
    mx = moment_w[i, 0]
    my = moment_w[i, 1]
    for k in range(4):
        mx -= tension[i, k] * arm[i, k] * sin_phi[i, k]
        my += tension[i, k] * arm[i, k] * cos_phi[i, k]
    out[i, 0] = kappa_rest[i, 0] + mx / ei_nmm2[i]
    out[i, 1] = kappa_rest[i, 1] + my / ei_nmm2[i]


@njit(cache=True)
def _walk(drive_n, h_mm, ei_nmm2, r_mm, give_mm_per_n, cos_phi, sin_phi, ea_axial_n, kappa_rest, kappa_set,
          moment_w, c_drive_mm_per_n, ea_tendon_n, mu, c0_n_per_mm, pull_mm, tension_prev,
          tension, sens, arm, kappa, rotation, position, residual, jacobian):
    """Tensions, curvature and backbone for drive tensions `drive_n`; fills residual g and its Jacobian."""
    m = tension.shape[0]
    q = np.empty((3, 3))
    d = np.empty(3)
    slope = np.empty(4)
    for k in range(4):
        tension[0, k] = drive_n[k]
        sens[0, k] = 1.0
        arm[0, k] = _arm(r_mm[0], give_mm_per_n[0], drive_n[k])
    _curvature(0, tension, arm, cos_phi, sin_phi, ei_nmm2, kappa_rest, moment_w, kappa)
    for a in range(3):
        for b in range(3):
            rotation[0, a, b] = 1.0 if a == b else 0.0
    position[0, :] = 0.0
    c0_h = c0_n_per_mm * h_mm
    for i in range(1, m):
        # predictor: wrap of the segment from its proximal curvature; corrector: from its mean
        kx = kappa[i - 1, 0]
        ky = kappa[i - 1, 1]
        for sweep in range(2):
            bend = math.hypot(kx, ky)
            wrap = bend * h_mm
            for k in range(4):
                # d wrap / d T_k: d(T_k a_k)/dT_k along the bend direction, over EI (a_k at the
                # proximal tension: this only steers the sensitivity)
                wrap_per_n = 0.0
                if bend > 0.0:
                    lever = _moment_slope(r_mm[i], give_mm_per_n[i], _arm(r_mm[i], give_mm_per_n[i], tension[i - 1, k]))
                    wrap_per_n = h_mm * lever * (ky * cos_phi[i, k] - kx * sin_phi[i, k]) / (bend * ei_nmm2[i])
                tension[i, k], sens[i, k] = clamp_to_capstan(tension_prev[i, k], tension[i - 1, k], sens[i - 1, k],
                                                             mu[k], wrap, wrap_per_n, c0_h)
                if tension[i, k] < 0.0:
                    tension[i, k] = 0.0
                    sens[i, k] = 0.0
                arm[i, k] = _arm(r_mm[i], give_mm_per_n[i], tension[i, k])
            _curvature(i, tension, arm, cos_phi, sin_phi, ei_nmm2, kappa_rest, moment_w, kappa)
            kx = 0.5 * (kappa[i - 1, 0] + kappa[i, 0])
            ky = 0.5 * (kappa[i - 1, 1] + kappa[i, 1])
        sum_prev = tension[i - 1, 0] + tension[i - 1, 1] + tension[i - 1, 2] + tension[i - 1, 3]
        sum_here = tension[i, 0] + tension[i, 1] + tension[i, 2] + tension[i, 3]
        strain = -0.5 * (sum_prev / ea_axial_n[i - 1] + sum_here / ea_axial_n[i])
        segment_displacement(kx, ky, h_mm, 1.0 + strain, d)
        for a in range(3):
            position[i, a] = position[i - 1, a] + (rotation[i - 1, a, 0] * d[0] + rotation[i - 1, a, 1] * d[1]
                                                   + rotation[i - 1, a, 2] * d[2])
        segment_rotation(kx, ky, h_mm, q)
        for a in range(3):
            for b in range(3):
                rotation[i, a, b] = (rotation[i - 1, a, 0] * q[0, b] + rotation[i - 1, a, 1] * q[1, b]
                                     + rotation[i - 1, a, 2] * q[2, b])
    # compatibility residual and Jacobian (trapezoid weights)
    for k in range(4):
        residual[k] = c_drive_mm_per_n * drive_n[k] - pull_mm[k]
        for j in range(4):
            jacobian[k, j] = c_drive_mm_per_n if k == j else 0.0
    for i in range(m):
        w = 0.5 * h_mm if (i == 0 or i == m - 1) else h_mm
        total = tension[i, 0] + tension[i, 1] + tension[i, 2] + tension[i, 3]
        dkx = kappa[i, 0] - kappa_set[i, 0]
        dky = kappa[i, 1] - kappa_set[i, 1]
        for j in range(4):
            slope[j] = _moment_slope(r_mm[i], give_mm_per_n[i], arm[i, j])
        for k in range(4):
            ck = cos_phi[i, k]
            sk = sin_phi[i, k]
            shortening = dky * ck - dkx * sk
            residual[k] += w * (arm[i, k] * shortening + tension[i, k] / ea_tendon_n + total / ea_axial_n[i])
            for j in range(4):
                if sens[i, j] == 0.0:
                    continue
                # cos(phi_k - phi_j) = cos phi_k cos phi_j + sin phi_k sin phi_j
                g = arm[i, k] * slope[j] * (ck * cos_phi[i, j] + sk * sin_phi[i, j]) / ei_nmm2[i] + 1.0 / ea_axial_n[i]
                if k == j:
                    g += 1.0 / ea_tendon_n - give_mm_per_n[i] * arm[i, k] * arm[i, k] / (r_mm[i] * r_mm[i]) * shortening
                jacobian[k, j] += w * sens[i, j] * g


@njit(cache=True)
def solve_step(h_mm, ei_nmm2, r_mm, give_mm_per_n, cos_phi, sin_phi, ea_axial_n, kappa_rest, kappa_set, weight_n,
               c_drive_mm_per_n, ea_tendon_n, mu, c0_n_per_mm, pull_mm, tension_prev, drive_n,
               tension, kappa, rotation, position, tol_mm, max_iterations):
    """Projected Newton on the drive tensions `drive_n` (in: the guess, out: the solution).

    Each Newton step is backtracked (halved up to BACKTRACKS times) until |g| decreases: the
    return mapping makes g only piecewise smooth, with kinks where a slip zone ends.
    `rotation` and `position` come in with the latest shape (for the weight's moment) and go out
    with the solution's; `tension` and `kappa` go out with the solution's profiles. Returns the
    number of iterations, or -1 if max_iterations passed without |g| < tol_mm (and, with weight,
    without the tip settling to tol_mm).
    """
    m = tension.shape[0]
    sens = np.empty((m, 4))
    arm = np.empty((m, 4))
    moment_w = np.zeros((m, 2))
    residual = np.empty(4)
    jacobian = np.empty((4, 4))
    trial_residual = np.empty(4)
    trial_jacobian = np.empty((4, 4))
    trial_drive = np.empty(4)
    has_weight = np.any(weight_n != 0.0)
    last_tip = np.full(3, np.inf)
    if has_weight:
        weight_moments_body(position, rotation, weight_n, moment_w)
    _walk(drive_n, h_mm, ei_nmm2, r_mm, give_mm_per_n, cos_phi, sin_phi, ea_axial_n, kappa_rest, kappa_set,
          moment_w, c_drive_mm_per_n, ea_tendon_n, mu, c0_n_per_mm, pull_mm, tension_prev,
          tension, sens, arm, kappa, rotation, position, residual, jacobian)
    for iteration in range(max_iterations):
        # a tendon at zero tension that would need to push is slack: hold it at zero
        held = np.zeros(4, dtype=np.bool_)
        for k in range(4):
            held[k] = drive_n[k] <= 0.0 and residual[k] >= 0.0
        norm = _free_norm(residual, held)
        settled = True
        if has_weight:
            for a in range(3):
                settled = settled and abs(position[m - 1, a] - last_tip[a]) < tol_mm
                last_tip[a] = position[m - 1, a]
            weight_moments_body(position, rotation, weight_n, moment_w)
        if norm < tol_mm and settled:
            return iteration + 1
        for k in range(4):
            if held[k]:
                for j in range(4):
                    jacobian[k, j] = 0.0
                    jacobian[j, k] = 0.0
                jacobian[k, k] = 1.0
                residual[k] = 0.0
        step = np.linalg.solve(jacobian, -residual)
        # backtrack while |g| does not decrease; if no fraction of the step decreases it (a
        # kink: the slip zones change), take the whole step (non-monotone, leaves the kink)
        scale = 1.0
        for attempt in range(BACKTRACKS + 1):
            if attempt == BACKTRACKS:
                scale = 1.0
            for k in range(4):
                trial_drive[k] = max(drive_n[k] + scale * step[k], 0.0)
            _walk(trial_drive, h_mm, ei_nmm2, r_mm, give_mm_per_n, cos_phi, sin_phi, ea_axial_n, kappa_rest,
                  kappa_set, moment_w, c_drive_mm_per_n, ea_tendon_n, mu, c0_n_per_mm, pull_mm, tension_prev,
                  tension, sens, arm, kappa, rotation, position, trial_residual, trial_jacobian)
            trial_held = np.zeros(4, dtype=np.bool_)
            for k in range(4):
                trial_held[k] = trial_drive[k] <= 0.0 and trial_residual[k] >= 0.0
            if _free_norm(trial_residual, trial_held) < norm:
                break
            scale *= 0.5
        drive_n[:] = trial_drive
        residual[:] = trial_residual
        jacobian[:, :] = trial_jacobian
    return -1


@njit(cache=True)
def _free_norm(residual, held):
    """max |g_k| over the tendons not held slack [mm]."""
    worst = 0.0
    for k in range(4):
        if not held[k]:
            worst = max(worst, abs(residual[k]))
    return worst
