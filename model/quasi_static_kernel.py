"""The one kernel of the lumped Dahl catheter: a quasi-static step, compiled with numba.

Generalised coordinates (seed paper II.A). Element i (i = 0 at the base, N-1 at the tip) of
length h = L/N has a bend b_i = (bx, by) [rad] and an axial compression c_i [mm]. Bending
and axial springs sit on each element, so in these coordinates the stiffness is diagonal:
K_b = EI/h [N*mm/rad], K_a = EA/h [N/mm]. The kernel is linear; cost grows linearly in N.

Quasi-static motion (paper I.A). Inertia and damping forces vanish at quasi-static rates,
so each step solves static equilibrium; the path still matters through the friction state.
The element masses (density*h) enter as gravity loads through the contact Jacobian.
Dynamic mode (paper I.A, Fig. 1: M q'' + C q' + K q = f with diagonal M and C): with a damping
time or an inertia scale set, each step is one backward-Euler step of the element bends, which
only stiffens each element's bend spring and shifts the bend it acts about
(`dynamic_bend_offset`); the solve below is otherwise the same.

Tendons (paper II.A-B). Tendon k sits at radius r and angle phi_k = (k-1)*90 deg (plus the
twist term), is fixed at the tip and pulled by u_k [mm] at the base. Its tension just
distal of element i is T_k^tip + sum_{j>i} F_kj, where F_kj is the Dahl friction force of
the element it crosses (paper II.B: each more proximal tension adds the friction of the
elements distal to it). With the mean tension over the element T_ki = T_k^tip +
sum_{j>i} F_kj + F_ki/2, equilibrium of element i is

    b_i = b_rest,i + b_ext,i + (r/K_b) * sum_k T_ki e_k,       e_k = (cos phi_k, sin phi_k)
    c_i = (h/EA) * sum_k T_ki

and the lumen of tendon k shortens by delta_ki = c_i + r (b_i - b_rest,i).e_k; the tendon
itself stretches by (h/EA_t) T_ki. Compatibility of an inextensible, taut tendon is

    sum_i [delta_ki + (h/EA_t) T_ki] + c_drive * T_k^drive = u_k         (T_k^tip >= 0)

and a tendon that would need to push is slack (zero tension). Sliding of tendon k past the
centre of element i (toward the base) is x_ki = sum_{j>i} delta'_kj + delta'_ki(P)/2, with
delta' the shortening plus stretch and P the tension of the element's distal half (the
friction force acts at the centre, so it loads only the proximal half). The Dahl force
follows paper eq. 1 with Fs from eq. 3.

Implicit solution. Everything at element i is affine in the four tip tensions, because the
friction increment is linearised, F_ki = F_ki^0 + k_ki (x_ki - x_ki^0) + g_ki (T_ki - T_ki^0). One sweep from
tip to base carries these affine maps (a 4x4 solve per element), compatibility then gives
the tip tensions (a 4x4 complementarity problem for slack tendons). Newton iterations
re-linearise each element about the last iterate, in sliding and in mean tension (the
capstan dependence of Fs), with the derivatives of the exactly integrated Dahl law, until
the exact and the linearised friction forces agree. This is unconditionally stable for stiff friction, unlike the
explicit use of the previous step's friction.
"""
import math

import numpy as np
from model.jit import kernel

from model.backbone_geometry import compose_backbone
from model.dahl_friction import capstan_gain, dahl_update_with_slopes
from model.effect_terms import (E_BACKLASH, E_CREEP_COMPLIANCE, E_CREEP_TIME, E_GX, E_GY, E_GZ, E_KAPPA0_X,
                                E_KAPPA0_Y, E_LUMEN_COEF, E_LUMEN_EXTENT, E_RATE, E_SENSOR_X, E_TENDON_COMPLIANCE,
                                E_TRACKER_X, E_TUBE_PLAY, E_TWIST)
from model.linear_algebra import solve_in_place

# Positions in the kernel's parameter vector (see DahlCatheter._kernel_params).
P_R = 0        # tendon offset r, mm
P_EI = 1       # bending stiffness EI, N*mm^2
P_EA = 2       # axial stiffness EA, N
P_EAT = 3      # tendon axial stiffness EA_t, N
P_MU = 4       # capstan friction coefficient
P_FSC = 5      # constant friction per mm of length, N/mm
P_SIGMA = 6    # Dahl stiffness per mm of length, N/mm^2
P_ALPHA = 7    # Dahl exponent
P_RHO = 8      # linear density, kg/mm
P_TAU = 9      # bending damping time constant tau = eta/EI, s (dynamic mode)
P_INERTIA = 10  # inertia scale on the first-mode inertia of the linear density (dynamic mode)
N_PARAMS = 11

# Positions in the state's diagnostics vector.
S_ITERATIONS = 0    # Newton iterations used in total
S_UNCONVERGED = 1   # steps that hit the iteration limit
N_SCALARS = 2

CANTILEVER_MODE_1 = 12.362   # (beta_1 L)^4 = 1.8751^4: first bending mode of a clamped-free beam
MAX_NEWTON_ITERATIONS = 12   # default Newton iterations of a sub-step before it is retried in halves
MAX_HALVINGS = 10   # an unconverged sub-step is retried in halves, down to 1/1024 of it
TIGHTENING_HALVINGS = 4   # a sub-step in which a slack tendon tightens is retried in halves, down to 1/16 of it
MAX_TENSION_STEP_N = 1.0  # a sub-step switching slack tendons and a drive tension by more is retried in halves
FORCE_TOLERANCE_N = 1e-4  # exact vs linearised Dahl force per element; 1e-4 N moves the tip < 1 um


@kernel
def play_operator(previous: float, target: float, width: float) -> float:
    """Backlash (play) of total width w: the output follows once the input leaves the band.

        y = min(max(y_prev, x - w/2), x + w/2)
    """
    half = 0.5 * width
    return min(max(previous, target - half), target + half)


@kernel
def _element_modifiers(n, length, params, effects, point_loads, tension, points, frames,
                       arm, angle, rest_bend, ext_bend):
    """Per-element terms from the effect vector, the external loads and the previous step's state.

    arm_i = r / (1 + c_lumen * sum_k T_ki * exp(-s_i / extent))      (lumen compression)
    angle offset_i = twist * (i + 1/2) / N                           (torsion)
    b_rest,i = kappa0 * h                                            (precurvature)
    b_ext,i = (M_y, -M_x) / K_b: the generalised force J^T F of the loads distal to element i's
    base p_i (seed paper II: external forces through the contact-point Jacobian), with
        M_i = sum_{j>=i} (c_j - p_i) x (m_j g)  +  sum_{loads at s > s_i} (q - p_i) x F
    in the frame of element i: the element weights (gravity effect) at the element centres c_j,
    and the point loads (fx, fy, fz [N], distance d [mm] from the tip) at the backbone point
    q at arc length s = L - d. Loads inside the support tube (d >= L) act on the tube. The
    moment arms come from the previous step's shape; the axial part of the loads is neglected
    (EA is orders stiffer than the tendon loads need).
    """
    h = length / n
    kb = params[P_EI] / h
    for i in range(n):
        arm[i] = params[P_R]
        if effects[E_LUMEN_COEF] > 0.0:
            load = 0.0
            for k in range(4):
                load += max(tension[k, i], 0.0)
            s_mid = (i + 0.5) * h
            arm[i] /= 1.0 + effects[E_LUMEN_COEF] * load * math.exp(-s_mid / effects[E_LUMEN_EXTENT])
        angle[i] = effects[E_TWIST] * (i + 0.5) / n
        rest_bend[i, 0] = effects[E_KAPPA0_X] * h
        rest_bend[i, 1] = effects[E_KAPPA0_Y] * h
        ext_bend[i, 0] = 0.0
        ext_bend[i, 1] = 0.0
    weight = params[P_RHO] * h
    f0 = weight * effects[E_GX]
    f1 = weight * effects[E_GY]
    f2 = weight * effects[E_GZ]
    if f0 == 0.0 and f1 == 0.0 and f2 == 0.0 and point_loads.shape[0] == 0:
        return
    sum_f = np.zeros(3)      # total load distal to the current element's base
    sum_pxf = np.zeros(3)    # and its moment about the origin
    for i in range(n - 1, -1, -1):
        c0 = 0.5 * (points[i, 0] + points[i + 1, 0])
        c1 = 0.5 * (points[i, 1] + points[i + 1, 1])
        c2 = 0.5 * (points[i, 2] + points[i + 1, 2])
        _add_load(c0, c1, c2, f0, f1, f2, sum_f, sum_pxf)
        for m in range(point_loads.shape[0]):
            s_load = length - point_loads[m, 3]
            if i * h <= s_load and (s_load < (i + 1) * h or (i == n - 1 and s_load <= length)):
                w = s_load / h - i
                _add_load(points[i, 0] + w * (points[i + 1, 0] - points[i, 0]),
                          points[i, 1] + w * (points[i + 1, 1] - points[i, 1]),
                          points[i, 2] + w * (points[i + 1, 2] - points[i, 2]),
                          point_loads[m, 0], point_loads[m, 1], point_loads[m, 2], sum_f, sum_pxf)
        p0 = points[i, 0]
        p1 = points[i, 1]
        p2 = points[i, 2]
        m0 = sum_pxf[0] - (p1 * sum_f[2] - p2 * sum_f[1])
        m1 = sum_pxf[1] - (p2 * sum_f[0] - p0 * sum_f[2])
        m2 = sum_pxf[2] - (p0 * sum_f[1] - p1 * sum_f[0])
        local_x = frames[i, 0, 0] * m0 + frames[i, 1, 0] * m1 + frames[i, 2, 0] * m2
        local_y = frames[i, 0, 1] * m0 + frames[i, 1, 1] * m1 + frames[i, 2, 1] * m2
        ext_bend[i, 0] = local_y / kb
        ext_bend[i, 1] = -local_x / kb


@kernel
def _add_load(q0, q1, q2, f0, f1, f2, sum_f, sum_pxf):
    """Add the force f at the point q to the running total force and its moment q x f about the origin."""
    sum_f[0] += f0
    sum_f[1] += f1
    sum_f[2] += f2
    sum_pxf[0] += q1 * f2 - q2 * f1
    sum_pxf[1] += q2 * f0 - q0 * f2
    sum_pxf[2] += q0 * f1 - q1 * f0


@kernel
def _sweep(n, h, kb, params, arm, cos_phi, sin_phi, ext_bend, f0, kx, gt, gth, bend_dir, xref, tref, slack,
           lin_force, dist_force, dist_short, scratch):
    """Tip-to-base sweep: affine maps (4 x 5: constant, then d/dT_tip) of the friction forces.

    Stores the map of each element's friction forces (lin_force) and returns the maps of the
    distal sums of force and shortening over the whole catheter (dist_force, dist_short).

    Friction is linearised about the last iterate (x_ref, T_ref, F0):
        F = F0 + K (x - x_ref) + G (T - T_ref),   T = P + F/2,   x = S + (D P + d0)/2
    with P = T_tip + C_dist the tension of the element's distal half and S = S_dist the distal
    shortening: the sliding at the element's centre comes from the distal half only, which
    carries P, not F. That gives per element
        (I - G/2) F = F0 + K (S + D P/2 + d0/2 - x_ref) + G (P - T_ref).
    K = diag(dF/dx). G_km = dF_k/dT_m holds the capstan dependence of Fs on the tendon's own
    tension, gt_k (k = m), and on the element angle theta, which every tension bends:
    gth_k * dtheta/dT_m with dtheta/dT_m = (r/K_b) (u . e_m), u the unit bend direction.
    So I - G/2 = Delta - (1/2) gth w^T: diagonal plus rank one (`_solve_diagonal_plus_rank_one`).
    A slack tendon's row is F = 0.
    kb is the element's bending stiffness as the step sees it (K_b, or K_b + m/dt^2 + c/dt in the
    dynamic mode) and ext_bend the bend offset it acts about (see dynamic_bend_offset).
    """
    ka = h / params[P_EA]
    kt = h / params[P_EAT]
    inv_diag, coupling, rhs, pull, dp, w_pull, d0, w = scratch
    dist_force[:, :] = 0.0
    dist_short[:, :] = 0.0
    for i in range(n - 1, -1, -1):
        r = arm[i]
        c = r * r / kb
        # the element's tendon directions as values: an array view here costs two reference
        # counts per element and iteration (3% of the benchmark step)
        e0 = (cos_phi[i, 0], cos_phi[i, 1], cos_phi[i, 2], cos_phi[i, 3])
        e1 = (sin_phi[i, 0], sin_phi[i, 1], sin_phi[i, 2], sin_phi[i, 3])
        for m in range(4):   # dtheta/dT_m = (r/K_b) u . e_m
            w[m] = r / kb * (bend_dir[i, 0] * e0[m] + bend_dir[i, 1] * e1[m])
        for k in range(4):
            d0[k] = r * (ext_bend[i, 0] * e0[k] + ext_bend[i, 1] * e1[k])
            for col in range(5):
                pull[k, col] = dist_force[k, col]
            pull[k, k + 1] += 1.0
        _apply_d(ka, c, kt, e0, e1, pull, dp)
        for col in range(5):
            w_pull[col] = w[0] * pull[0, col] + w[1] * pull[1, col] + w[2] * pull[2, col] + w[3] * pull[3, col]
        w_tref = w[0] * tref[0, i] + w[1] * tref[1, i] + w[2] * tref[2, i] + w[3] * tref[3, i]
        for k in range(4):
            if slack[k]:
                inv_diag[k] = 1.0
                coupling[k] = 0.0
                for col in range(5):
                    rhs[k, col] = 0.0
                continue
            kk = kx[k, i]
            gk = gt[k, i]
            hk = gth[k, i]
            inv_diag[k] = 1.0 / (1.0 - 0.5 * gk)
            coupling[k] = hk * inv_diag[k]
            for col in range(5):
                rhs[k, col] = inv_diag[k] * (kk * (dist_short[k, col] + 0.5 * dp[k, col]) + gk * pull[k, col]
                                             + hk * w_pull[col])
            rhs[k, 0] += inv_diag[k] * (f0[k, i] + kk * (0.5 * d0[k] - xref[k, i]) - gk * tref[k, i] - hk * w_tref)
        _solve_diagonal_plus_rank_one(coupling, w, rhs)
        for k in range(4):
            for col in range(5):
                force = rhs[k, col]
                lin_force[i, k, col] = force
                pull[k, col] += 0.5 * force       # now the element's mean tension T = P + F/2
                dist_force[k, col] += force
        _apply_d(ka, c, kt, e0, e1, pull, dp)
        for k in range(4):
            for col in range(5):
                dist_short[k, col] += dp[k, col]
            dist_short[k, 0] += d0[k]


@kernel
def _solve_diagonal_plus_rank_one(q, w, y):
    """Solve (Delta - (1/2) h w^T) X = B in place, given q = Delta^-1 h and y = Delta^-1 B.

    Sherman-Morrison: X = y + q (w^T y) / (2 - w^T q), column by column. The friction
    linearisation keeps 2 - w^T q well away from 0 (it is diagonally dominant).
    """
    wq = w[0] * q[0] + w[1] * q[1] + w[2] * q[2] + w[3] * q[3]
    scale = 1.0 / (2.0 - wq)
    for col in range(y.shape[1]):
        beta = scale * (w[0] * y[0, col] + w[1] * y[1, col] + w[2] * y[2, col] + w[3] * y[3, col])
        for k in range(4):
            y[k, col] += beta * q[k]


@kernel
def _apply_d(ka, c, kt, e0, e1, x, out):
    """out = D x for the element compliance D = ka*J + c*E E^T + kt*I (J all ones, E = [e0 e1], 4-tuples)."""
    for col in range(x.shape[1]):
        total = x[0, col] + x[1, col] + x[2, col] + x[3, col]
        along0 = e0[0] * x[0, col] + e0[1] * x[1, col] + e0[2] * x[2, col] + e0[3] * x[3, col]
        along1 = e1[0] * x[0, col] + e1[1] * x[1, col] + e1[2] * x[2, col] + e1[3] * x[3, col]
        for k in range(4):
            out[k, col] = ka * total + c * (e0[k] * along0 + e1[k] * along1) + kt * x[k, col]


@kernel
def _tip_tensions(u, compliance, dist_force, dist_short, slack, revived, tip_tension, scratch):
    """Compatibility with slack tendons: a 4-variable complementarity problem, by active set.

    G_k(T) = S_k(T) + c_drive*(T_k + C_k(T)) is the length the tendon path takes up.
    Taut: G_k(T) = u_k with T_k >= 0. Slack: T_k = 0 with G_k(T) >= u_k.
    A tendon re-tightened during this step (`revived`) stays taut for the step: pulled against
    its own friction it may carry a small negative tip tension (at most its friction), since the
    model does not resolve partial slack along one tendon.
    Updates `slack` and `revived` in place; returns True if the set of slack tendons changed.
    """
    g, assumed, active, mat, vec, idx = scratch
    for k in range(4):
        for col in range(5):
            basis = 1.0 if (col == k + 1) else 0.0
            g[k, col] = dist_short[k, col] + compliance * (basis + dist_force[k, col])
    assumed[:] = slack
    active[:] = slack
    for _ in range(10):
        nt = 0
        for k in range(4):
            if not active[k]:
                idx[nt] = k
                nt += 1
        for a in range(nt):
            for b in range(nt):
                mat[a, b] = g[idx[a], idx[b] + 1]
            vec[a, 0] = u[idx[a]] - g[idx[a], 0]
        for k in range(4):
            tip_tension[k] = 0.0
        if nt > 0:
            solve_in_place(mat, vec, nt, 1)
            for a in range(nt):
                tip_tension[idx[a]] = vec[a, 0]
        worst = -1
        worst_value = -1e-12
        for k in range(4):
            if not active[k] and not revived[k] and tip_tension[k] < worst_value:
                worst_value = tip_tension[k]
                worst = k
        if worst >= 0:
            active[worst] = True
            continue
        retightened = False
        for k in range(4):
            if active[k]:
                taken = g[k, 0]
                for m in range(4):
                    taken += g[k, m + 1] * tip_tension[m]
                if taken < u[k] - 1e-12:
                    active[k] = False
                    retightened = True
                    break
        if not retightened:
            break
    changed = False
    for k in range(4):
        if active[k] != assumed[k]:
            changed = True
            if assumed[k]:
                revived[k] = True
        slack[k] = active[k]
    return changed


@kernel
def _linearise_element(i, bx, by, mu, fsc, sigma, alpha, rate_scale, friction, increment, tension,
                       slack, f0, kx, gt, gth, bend_dir, strength):
    """Exact Dahl forces of element i after the sliding `increment`, and their derivatives.

    Slack tendons get zeros. Fs = s_k*(Fsc + gain(theta)*T) with gain = 2 tanh(mu theta/2)
    (capstan_gain) and the rate-friction scale s_k of tendon k (fixed within the step, see
    run_path). Returns, per tendon, F0 = dahl_update(...), dF/dx, gt = dF/dFs * s*gain (own
    tension), gth = dF/dFs * s*T*dgain/dtheta with dgain/dtheta = mu*(1 - tanh^2(mu theta/2)),
    and the strength Fs itself.
    """
    theta = math.sqrt(bx * bx + by * by)
    gain = capstan_gain(mu, theta)
    dgain = mu * (1.0 - 0.25 * gain * gain)
    if theta > 1e-12:
        bend_dir[i, 0] = bx / theta
        bend_dir[i, 1] = by / theta
    else:
        bend_dir[i, 0] = 0.0
        bend_dir[i, 1] = 0.0
    for k in range(4):
        if slack[k]:       # a slack tendon carries no friction
            f0[k, i] = 0.0
            kx[k, i] = 0.0
            gt[k, i] = 0.0
            gth[k, i] = 0.0
            strength[k, i] = 0.0
            continue
        s = rate_scale[k]
        t = max(tension[k, i], 0.0)
        fs = s * (fsc + gain * t)
        strength[k, i] = fs
        force, d_dx, d_fs = dahl_update_with_slopes(friction[k, i], increment[k, i], fs, sigma, alpha)
        f0[k, i] = force
        kx[k, i] = d_dx
        gt[k, i] = d_fs * s * gain if tension[k, i] > 0.0 else 0.0
        gth[k, i] = d_fs * s * t * dgain


@kernel
def drive_creep(effects, dt_s):
    """Drive-line compliance as one step of dt_s [s] sees it, and the share of the old creep it keeps.

    The drive line stretches elastically, c*T, plus a creep s_c of a standard linear solid,
        s_c + tau ds_c/dt = c_creep T        (T the drive tension [N], tau [s], c_creep [mm/N])
    Backward Euler over dt: s_c = (c_creep T + (tau/dt) s_c,n) / (1 + tau/dt), so the
    compatibility equation (see _tip_tensions) takes
        compliance = c + c_creep/(1 + tau/dt),   u_step = u - carry*s_c,n,   carry = (tau/dt)/(1 + tau/dt)
    and s_c = carry*s_c,n + (compliance - c)*T after the step. dt = inf (a move to rest) is the
    fully crept, purely elastic c + c_creep. Returns (compliance [mm/N], carry [-]).
    """
    creep_compliance = effects[E_CREEP_COMPLIANCE]
    if creep_compliance == 0.0:
        return effects[E_TENDON_COMPLIANCE], 0.0
    ratio = effects[E_CREEP_TIME] / dt_s if math.isfinite(dt_s) else 0.0
    return effects[E_TENDON_COMPLIANCE] + creep_compliance / (1.0 + ratio), ratio / (1.0 + ratio)


@kernel
def has_dynamics(params):
    """The dynamic mode is on when the bends have damping or inertia (CatheterParams [dynamics])."""
    return params[P_TAU] > 0.0 or params[P_INERTIA] > 0.0


@kernel
def dynamic_bend_offset(length, kb, dt_s, params, rest_bend, ext_bend, bend, bend_rate, offset):
    """One backward-Euler step of the element bends (seed paper I.A, Fig. 1): stiffness and offset.

    Each element's bend b_i (2-vector, rad) obeys M q'' + C q' + K q = f with diagonal M and C
    (paper I.A: "a decoupled, diagonal mass matrix"), the tendon moments r*sum_k T_ki e_k as the
    control input (the tendon tensions are whatever balances the spring, damper and inertia forces,
    paper II.B), friction through those tensions, and external loads in K_b b_ext:

        m b'' + c b' + K_b (b - b_rest - b_ext) = r sum_k T_ki e_k

    Per element of length h = L/N, with the Kelvin-Voigt damping time tau = eta/EI [s] and the
    inertia scale s_m [-]:
        K_b = EI/h [N*mm/rad],  c = tau*K_b [N*mm*s/rad],
        m = s_m * 1e-3 * rho*L^4 / (12.362*h) [N*mm*s^2/rad]   (rho in kg/mm; 1 N*mm*s^2 = 1e3 kg*mm^2)
    so that sqrt(K_b/m) = sqrt(12.362*EI/(rho*L^4)) (x sqrt(1/s_m)) is the first bending mode of the
    clamped-free beam of this density, and tau and the damping ratio zeta = tau*omega/2 are the
    same in every element: the response does not depend on N (paper II.B, invariance to N).
    Backward Euler over dt [s] (implicit, L-stable: no overshoot or ringing from the integrator),
        b' = (b - b_n)/dt,   b'' = (b - b_n)/dt^2 - b_n'/dt,
    turns the element equation into the static one with a stiffer spring about a shifted bend:
        K_step = K_b + a,   a = m/dt^2 + c/dt
        b - b_rest = offset + (r/K_step) sum_k T_ki e_k,
        offset = (K_b b_ext + a (b_n - b_rest) + (m/dt) b_n') / K_step
    Both are per-element constants within the step, so the tip-to-base sweep, the 4x4
    compatibility solve and the cost linear in N stay as they are. dt = inf gives a = 0:
    the quasi-static solution. The axial springs stay static (EA/h is some 10^5 times K_b/r^2;
    their mode is far above any sample rate). Writes offset, returns K_step.
    """
    n = bend.shape[0]
    h = length / n
    inertia = params[P_INERTIA] * 1e-3 * params[P_RHO] * length ** 4 / (CANTILEVER_MODE_1 * h)
    damping = params[P_TAU] * kb
    if math.isfinite(dt_s):
        a = inertia / (dt_s * dt_s) + damping / dt_s
        carry = inertia / dt_s
    else:
        a = 0.0
        carry = 0.0
    k_step = kb + a
    for i in range(n):
        for j in range(2):
            offset[i, j] = (kb * ext_bend[i, j] + a * (bend[i, j] - rest_bend[i, j]) + carry * bend_rate[i, j]) / k_step
    return k_step


@kernel
def make_workspace(n):
    """Scratch arrays for quasi_static_step, allocated once per run."""
    return (np.empty(n), np.empty(n), np.empty((n, 2)), np.empty((n, 2)), np.empty((n, 4)), np.empty((n, 4)),
            np.empty((4, n)), np.empty((4, n)), np.empty((4, n)), np.empty((4, n)), np.empty((n, 2)),
            np.empty((4, n)), np.empty((4, n)), np.empty((n, 4, 5)), np.empty(4), np.empty(4),
            np.empty((4, 5)), np.empty((4, 5)), np.empty((4, n)), np.empty((4, n)),
            np.empty((4, n)), np.empty((n, 2)), np.empty(n), np.empty((4, n)), np.empty(4),
            np.zeros(4, dtype=np.bool_), np.empty(n), np.zeros((4, n), dtype=np.bool_), np.zeros((4, n), dtype=np.bool_),
            np.empty(4),
            np.zeros((4, n), dtype=np.bool_), np.zeros(4, dtype=np.bool_),
            (np.empty(4), np.empty(4), np.empty((4, 5)), np.empty((4, 5)), np.empty((4, 5)), np.empty(5), np.empty(4),
             np.empty(4)),
            (np.empty((4, 5)), np.zeros(4, dtype=np.bool_), np.zeros(4, dtype=np.bool_), np.empty((4, 4)),
             np.empty((4, 1)), np.empty(4, dtype=np.int64)),
            np.empty((n, 2)), np.empty(4), np.empty((4, n)))


@kernel
def quasi_static_step(u, length, rate_scale, params, effects, point_loads, friction, sliding, last_step, tension,
                      last_tension_step, bend, compression, tip_tension, drive_tension, slack, points, frames,
                      scalars, work, max_iterations, commit_unconverged, dt_s, bend_rate, creep, extrapolate,
                      refine_tightening):
    """Advance the catheter state to equilibrium at tendon input u [mm] and free length [mm].

    In the dynamic mode (damping time or inertia scale > 0, see `has_dynamics`) the step is one
    backward-Euler step of dt_s [s] (inf: the quasi-static limit) of the element bends, through
    the stiffness and bend offset of `dynamic_bend_offset`; bend_rate [rad/s] is then updated.
    Without it, bend_rate is not touched and the step is the static solve, whatever dt_s is.
    creep [mm]: the drive line's creep stretch (`drive_creep`), updated over dt_s.
    extrapolate: start Newton from the last step's tension trend (see below; False on a retry).
    refine_tightening: a converged step in which a slack tendon tightens is not taken (False is
    returned, for the caller to retry it in halves; see run_path).

    `rate_scale[k]` multiplies tendon k's friction strength (rate friction, 1 without it).
    `work` is scratch space from make_workspace. Returns
    True when Newton converged within max_iterations; the state arrays are then updated in place. An unconverged
    step leaves the state untouched (the caller retries with a smaller step) unless
    `commit_unconverged`.
    """
    n = bend.shape[0]
    h = length / n
    kb = params[P_EI] / h
    sigma = params[P_SIGMA] * h
    fsc = params[P_FSC] * h
    mu = params[P_MU]
    alpha = params[P_ALPHA]

    (arm, angle, rest_bend, ext_bend, cos_phi, sin_phi, f0, kx, gt, gth, bend_dir, xref, tref, lin_force,
     distal_force, distal_short, dist_force, dist_short, new_force, new_sliding, new_tension,
     new_bend, new_compression, increment, linear_force, revived, lengths, clamped, released, previous_increment,
     crossed, slack_before, sweep_scratch, tip_scratch, dynamic_offset, u_step, strength) = work
    compliance, carry = drive_creep(effects, dt_s)
    for k in range(4):
        u_step[k] = u[k] - carry * creep[k]
    _element_modifiers(n, length, params, effects, point_loads, tension, points, frames,
                       arm, angle, rest_bend, ext_bend)
    dynamic = has_dynamics(params)
    offset = ext_bend          # bend about which the tendons act, minus the rest bend
    kb_step = kb               # the element's stiffness as this step sees it
    if dynamic:
        kb_step = dynamic_bend_offset(length, kb, dt_s, params, rest_bend, ext_bend, bend, bend_rate,
                                      dynamic_offset)
        offset = dynamic_offset
    for i in range(n):  # tendon k at phi_k = k*90 deg + twist offset
        c = math.cos(angle[i]) if angle[i] != 0.0 else 1.0
        s = math.sin(angle[i]) if angle[i] != 0.0 else 0.0
        cos_phi[i, 0], cos_phi[i, 1], cos_phi[i, 2], cos_phi[i, 3] = c, -s, -c, s
        sin_phi[i, 0], sin_phi[i, 1], sin_phi[i, 2], sin_phi[i, 3] = s, c, -s, -c

    # Linearisation of each friction element about (x_ref, T_ref, theta_ref, F0). First guess: this
    # step slides as far as the last one did (constant velocity), at the last tensions plus, in the
    # dynamic mode, the last step's change of them,
    #     T_ref = T + dT_last   (dT_last = 0 in the quasi-static mode, see the commit below);
    # then Newton updates from the exact Dahl integration at each iterate. theta_ref is the bend
    # this step's own bend map gives at T_ref,
    #     b_ref = b_rest + offset + (r/K_step) sum_k T_ref,k e_k,
    # the map the sweep linearises (theta - theta_ref = w . (T - T_ref)). In the quasi-static mode
    # under unchanged loads that is the last bend; in the dynamic mode the last bend is off it by
    # the damper and inertia forces, and linearising there cost a second Newton iteration in most
    # steps (1.7 iterations per 10 ms step on the benchmark path; 1.14 about b_ref at the last
    # tensions, 1.07 with the tension trend).
    for i in range(n):
        for k in range(4):
            predicted = tension[k, i] + last_tension_step[k, i]
            tref[k, i] = predicted if (extrapolate and predicted > 0.0) else tension[k, i]
    for i in range(n):
        along0 = 0.0
        along1 = 0.0
        for k in range(4):
            along0 += tref[k, i] * cos_phi[i, k]
            along1 += tref[k, i] * sin_phi[i, k]
        _linearise_element(i, rest_bend[i, 0] + offset[i, 0] + arm[i] / kb_step * along0,
                           rest_bend[i, 1] + offset[i, 1] + arm[i] / kb_step * along1, mu, fsc, sigma, alpha,
                           rate_scale, friction, last_step, tref, slack, f0, kx, gt, gth, bend_dir, strength)
        for k in range(4):
            xref[k, i] = sliding[k, i] + last_step[k, i]

    increment[:, :] = 0.0
    revived[:] = False
    clamped[:, :] = False
    released[:, :] = False
    crossed[:, :] = False
    slack_before[:] = slack
    converged = False
    for iteration in range(max_iterations):
        scalars[S_ITERATIONS] += 1.0
        _sweep(n, h, kb_step, params, arm, cos_phi, sin_phi, offset, f0, kx, gt, gth, bend_dir, xref, tref, slack,
               lin_force, dist_force, dist_short, sweep_scratch)
        if _tip_tensions(u_step, compliance, dist_force, dist_short, slack, revived, tip_tension, tip_scratch):
            continue
        worst = 0.0
        finite = True          # max() drops NaN, so a diverged iterate is caught here
        ka = h / params[P_EA]
        kt = h / params[P_EAT]
        for k in range(4):
            distal_force[k] = 0.0
            distal_short[k] = 0.0
        for i in range(n - 1, -1, -1):   # tip to base: tensions add the distal friction forces
            r = arm[i]
            c = r * r / kb_step
            bx = rest_bend[i, 0] + offset[i, 0]
            by = rest_bend[i, 1] + offset[i, 1]
            total = 0.0
            along0 = 0.0
            along1 = 0.0
            distal_total = 0.0
            distal_along0 = 0.0
            distal_along1 = 0.0
            for k in range(4):
                linear = lin_force[i, k, 0]
                for m in range(4):
                    linear += lin_force[i, k, m + 1] * tip_tension[m]
                linear_force[k] = linear
                distal = tip_tension[k] + distal_force[k]
                distal_total += distal
                distal_along0 += distal * cos_phi[i, k]
                distal_along1 += distal * sin_phi[i, k]
                t = distal + 0.5 * linear
                new_tension[k, i] = t
                total += t
                along0 += t * cos_phi[i, k]
                along1 += t * sin_phi[i, k]
            bx += r / kb_step * along0
            by += r / kb_step * along1
            new_bend[i, 0] = bx
            new_bend[i, 1] = by
            new_compression[i] = ka * total
            for k in range(4):
                # delta = D T + d0 with D = ka*J + (r^2/K_b) E E^T + kt*I, for the mean tension T
                # (whole element) and for the distal half's tension P (sliding at the centre)
                external = r * (offset[i, 0] * cos_phi[i, k] + offset[i, 1] * sin_phi[i, k])
                shortening = (ka * total + c * (cos_phi[i, k] * along0 + sin_phi[i, k] * along1)
                              + kt * new_tension[k, i] + external)
                distal_half = (ka * distal_total + c * (cos_phi[i, k] * distal_along0 + sin_phi[i, k] * distal_along1)
                               + kt * (tip_tension[k] + distal_force[k]) + external)
                new_sliding[k, i] = distal_short[k] + 0.5 * distal_half
                distal_short[k] += shortening
                distal_force[k] += linear_force[k]
                increment[k, i] = new_sliding[k, i] - sliding[k, i]
            for k in range(4):
                previous_increment[k] = xref[k, i] - sliding[k, i]
            _linearise_element(i, bx, by, mu, fsc, sigma, alpha, rate_scale, friction, increment,
                               new_tension, slack, f0, kx, gt, gth, bend_dir, strength)
            for k in range(4):
                # Dahl has a kink at zero sliding (one-sided slopes differ up to 2 sigma). Where the
                # iterate crossed it (once in this step), the chord from the step's start replaces
                # the tangent, so Newton cannot jump back and forth across the kink. The chord starts
                # at the force of zero sliding, clip(F_prev, -Fs, Fs): where the tension fell, Fs
                # clips the held force, and a chord from F_prev itself grew without bound as the
                # iterate closed in on the kink (a 120 deg step: 6 mN never resolved).
                if increment[k, i] * previous_increment[k] < 0.0:
                    crossed[k, i] = True
                if crossed[k, i] and increment[k, i] != 0.0:
                    held = min(max(friction[k, i], -strength[k, i]), strength[k, i])
                    kx[k, i] = max((f0[k, i] - held) / increment[k, i], 0.0)
                # A tendon cannot be pushed: friction may at most unload the proximal half to zero,
                # so the exact law is F = max(F_dahl, -max(P, 0)). Clamped at F = -P > 0 it is linear
                # in the tension: K = 0, G = -2 about the point (T_ref, F0) = (P/2, -P) of that line
                # F = -2T (T = P + F/2); at F = 0 (P <= 0) it is constant. A clamped element stays
                # clamped for the step, so Newton cannot cycle on the kink, but is released once where
                # the Dahl force no longer reaches the floor (F_dahl > -P): that clamp is no
                # equilibrium, so its mismatch to the Dahl force counts; kept, a clamped element could
                # hold any tension P (one recording: 92 N at the tip, 0 N at the drive).
                distal_tension = tip_tension[k] + distal_force[k] - linear_force[k]
                floor = -max(distal_tension, 0.0)
                exact = f0[k, i]
                xref[k, i] = new_sliding[k, i]
                tref[k, i] = new_tension[k, i]
                if clamped[k, i] and exact > floor + FORCE_TOLERANCE_N and not released[k, i]:
                    clamped[k, i] = False      # released once per step, so Newton cannot cycle on it
                    released[k, i] = True
                elif not slack[k] and (f0[k, i] < floor or clamped[k, i]):
                    clamped[k, i] = True
                    exact = max(exact, floor)
                    f0[k, i] = floor
                    kx[k, i] = 0.0
                    gt[k, i] = -2.0 if distal_tension > 0.0 else 0.0
                    gth[k, i] = 0.0
                    tref[k, i] = distal_tension + 0.5 * floor
                new_force[k, i] = f0[k, i]
                mismatch = abs(exact - linear_force[k])
                if not math.isfinite(mismatch):
                    finite = False
                worst = max(worst, mismatch)
        if finite and worst < FORCE_TOLERANCE_N:
            converged = True
            break
    switched = False
    tightened = False
    for k in range(4):
        switched = switched or slack[k] != slack_before[k]
        tightened = tightened or (slack_before[k] and not slack[k])
    if converged and tightened and refine_tightening:
        converged = False
    if converged and switched and not commit_unconverged:
        # A converged solve may still have switched to another equilibrium: at a coarse sub-step
        # the slack/taut set can flip so that a loaded tendon drops its tension at once (one
        # recording: 6.5 N to 0 N and an 18 mm tip jump where 0.05 mm sub-steps move 0.3 mm).
        # A sub-step that changes the slack set and a drive tension by more than
        # MAX_TENSION_STEP_N is retried in halves.
        for k in range(4):
            drive = tip_tension[k]
            for i in range(n):
                drive += new_force[k, i]
            if abs(drive - drive_tension[k]) > MAX_TENSION_STEP_N:
                converged = False
    if not converged:
        if not commit_unconverged:
            slack[:] = slack_before
            return False
        scalars[S_UNCONVERGED] += 1.0
        if not (np.isfinite(new_force).all() and np.isfinite(new_tension).all() and np.isfinite(new_bend).all()):
            slack[:] = slack_before     # never commit a diverged solve: keep the last equilibrium,
            return True                 # the next step's global solve catches up with the input

    for k in range(4):
        drive = tip_tension[k]
        for i in range(n):
            last_step[k, i] = new_sliding[k, i] - sliding[k, i]
            # The tension trend for the next step's first guess: only in the dynamic mode, where the
            # dampers make tensions evolve smoothly in time. Under quasi-static holds and reversals
            # it is a poor guess; on a near-Coulomb stick-slip reversal it led Newton to a garbage
            # iterate (test_friction_never_pushes_a_tendon_even_when_it_dominates). No trend either
            # after an unconverged solve, a tendon going slack or taut, or a jump of more than
            # MAX_TENSION_STEP_N (a step input's transient, not a trend).
            change = new_tension[k, i] - tension[k, i]
            trend = dynamic and converged and slack[k] == slack_before[k] and abs(change) < MAX_TENSION_STEP_N
            last_tension_step[k, i] = change if trend else 0.0
            friction[k, i] = new_force[k, i]
            sliding[k, i] = new_sliding[k, i]
            tension[k, i] = new_tension[k, i]
            drive += new_force[k, i]
        drive_tension[k] = drive
        creep[k] = carry * creep[k] + (compliance - effects[E_TENDON_COMPLIANCE]) * drive
    for i in range(n):
        if dynamic:   # backward Euler: b' = (b - b_prev)/dt (0 in the quasi-static limit dt = inf)
            bend_rate[i, 0] = (new_bend[i, 0] - bend[i, 0]) / dt_s
            bend_rate[i, 1] = (new_bend[i, 1] - bend[i, 1]) / dt_s
        bend[i, 0] = new_bend[i, 0]
        bend[i, 1] = new_bend[i, 1]
        compression[i] = new_compression[i]
        lengths[i] = h - new_compression[i]
    compose_backbone(bend, lengths, points, frames)
    return True


@kernel
def remap_to_length(old_length, new_length, friction, sliding, last_step, tension, last_tension_step):
    """Carry the friction state along the material when the free length changes.

    The tendons are driven from the insertion block, so they move with the catheter body:
    material keeps its distance tau from the tip. Element i is centred at
    tau_i = L - (i + 1/2) L/N. Friction force per unit length, sliding and tension are
    interpolated in tau; material that leaves the support tube arrives straight with no
    friction load, carrying the sliding of the base.
    """
    n = friction.shape[1]
    if new_length == old_length:
        return
    h_old = old_length / n
    h_new = new_length / n
    old_force = friction.copy()
    old_sliding = sliding.copy()
    old_last_step = last_step.copy()
    old_tension = tension.copy()
    old_tension_step = last_tension_step.copy()
    for i in range(n):
        tau = new_length - (i + 0.5) * h_new
        # fractional index in the old elements: tau = L_old - (j + 1/2) h_old
        j = (old_length - tau) / h_old - 0.5
        for k in range(4):
            if j <= 0.0:
                fade = max(0.0, 1.0 + j)  # fades to zero over the last half element into the tube
                friction[k, i] = old_force[k, 0] / h_old * h_new * fade
                sliding[k, i] = old_sliding[k, 0]
                last_step[k, i] = old_last_step[k, 0]
                tension[k, i] = old_tension[k, 0]
                last_tension_step[k, i] = old_tension_step[k, 0]
            elif j >= n - 1:
                friction[k, i] = old_force[k, n - 1] / h_old * h_new
                sliding[k, i] = old_sliding[k, n - 1]
                last_step[k, i] = old_last_step[k, n - 1]
                tension[k, i] = old_tension[k, n - 1]
                last_tension_step[k, i] = old_tension_step[k, n - 1]
            else:
                j0 = int(j)
                w = j - j0
                friction[k, i] = ((1 - w) * old_force[k, j0] + w * old_force[k, j0 + 1]) / h_old * h_new
                sliding[k, i] = (1 - w) * old_sliding[k, j0] + w * old_sliding[k, j0 + 1]
                last_step[k, i] = (1 - w) * old_last_step[k, j0] + w * old_last_step[k, j0 + 1]
                tension[k, i] = (1 - w) * old_tension[k, j0] + w * old_tension[k, j0 + 1]
                last_tension_step[k, i] = (1 - w) * old_tension_step[k, j0] + w * old_tension_step[k, j0 + 1]


@kernel
def run_path(tendon_mm, insertion_mm, dt_s, max_tendon_step_mm, max_insertion_step_mm, max_iterations,
             iteration_budget, params, effects, point_loads, applied_tendon_mm, applied_insertion_mm, friction,
             sliding, last_step, tension, last_tension_step, bend, compression, tip_tension, drive_tension, slack,
             points, frames, scalars, tips_out, drive_tension_out, max_time_step_s, bend_rate, creep):
    """Drive the model along a sampled input path; tips_out[t] is the tip as the tracker sees it
    (p_tip + R_tip d + o: d the sensor's mount offset in the tip frame, o the tracker's registration
    offset in the base frame) and drive_tension_out[t] the tendon tensions at the drives after sample t.

    Returns the number of samples done: all of them, unless the Newton iterations of this call
    exceed iteration_budget (inf: no budget), where it stops at once (mid-sample, the state then
    describes no sample; the caller restores it). Where the solver crawls, halving sub-steps
    down to 1/2^MAX_HALVINGS, one sample can take 10^5 iterations.

    Inputs pass the drive-train plays first (backlash per tendon, tube play on insertion).
    point_loads (K, 4): external point forces (fx, fy, fz [N], distance from the tip [mm]).
    Each sample is split into sub-steps of at most max_tendon_step_mm / max_insertion_step_mm
    so that the friction state follows the path (history) and not just its end point; a sub-step
    whose Newton solve needs more than max_iterations is retried in halves (in the dynamic mode,
    starting Newton from the last tensions rather than their trend).

    A sub-step in which a slack tendon tightens is also retried in halves, down to
    1/2^TIGHTENING_HALVINGS of a sub-step: the friction a tendon picks up as it tightens depends on
    where in the sub-step it does, so without this the sub-step's length decided it, and that
    length depended on whether Newton had needed more than max_iterations. On one fitted log a
    1e-12 relative change of the friction coefficient moved a tightening from a whole sample
    (0.013 mm of travel) to its halves, left that tendon 0.035 N apart for 16 s and the training
    RMSE 8 % apart (0.225 against 0.244 mm): every finite difference of a fit from there pointed
    uphill. Located to 1/16 of a sub-step, the same log gave 0.260 mm under every change of
    1e-12 to 1e-6, with max_iterations 6, 8 or 12 and with 0.25 or 0.5 mm sub-steps, at 36 %
    more Newton iterations; a limit in mm of travel instead (0.04 mm) left that sample whole and
    the jump in place.

    Rate friction scales tendon k's friction strength by s_k = 1 + c_rate*|v_k| over the
    sample, v_k = (u_k(t) - u_k(t-1)) / dt_s its pull speed past the drive-train play (0 for
    dt_s = inf, a purely quasi-static move). The scale is known before the solve, so it adds
    no discontinuity to Newton's system (a scale on each element's own sliding increment did,
    at every reversal).

    Dynamic mode (`has_dynamics`): the input is linear in time over each sample, so a sub-step
    that covers the fraction w of the sample is a backward-Euler step of w*dt_s seconds; samples
    are also split so that no step exceeds max_time_step_s. dt_s = inf (a move to rest) is one
    quasi-static solve.
    """
    n_samples = tendon_mm.shape[0]
    target = np.empty(4)
    u = np.empty(4)
    start = np.empty(4)
    rate_scale = np.ones(4)
    rate_per_mm = effects[E_RATE] / dt_s if (dt_s > 0.0 and math.isfinite(dt_s)) else 0.0
    work = make_workspace(bend.shape[0])
    dynamic = has_dynamics(params)
    stop_at_iterations = scalars[S_ITERATIONS] + iteration_budget
    for t in range(n_samples):
        for k in range(4):
            target[k] = play_operator(applied_tendon_mm[k], tendon_mm[t, k], effects[E_BACKLASH])
        length_target = play_operator(applied_insertion_mm[0], insertion_mm[t], effects[E_TUBE_PLAY])
        span = 0.0
        for k in range(4):
            span = max(span, abs(target[k] - applied_tendon_mm[k]))
            rate_scale[k] = 1.0 + rate_per_mm * abs(target[k] - applied_tendon_mm[k])
        n_sub = max(1, int(math.ceil(span / max_tendon_step_mm)),
                    int(math.ceil(abs(length_target - applied_insertion_mm[0]) / max_insertion_step_mm)))
        if dynamic and math.isfinite(dt_s):
            n_sub = max(n_sub, int(math.ceil(dt_s / max_time_step_s - 1e-9)))
        start_length = applied_insertion_mm[0]
        start[:] = applied_tendon_mm
        length = start_length
        # Advance through the fraction w of the sample; a sub-step whose Newton solve does not
        # converge (a sharp friction reversal) is halved, down to 1/2^MAX_HALVINGS of a sub-step.
        done = 0.0
        retry = False
        fraction = 1.0 / n_sub
        smallest = fraction / 2.0 ** MAX_HALVINGS
        tightening_smallest = fraction / 2.0 ** TIGHTENING_HALVINGS
        while done < 1.0 - 1e-12:
            fraction = min(fraction, 1.0 - done)
            w = done + fraction
            for k in range(4):
                u[k] = start[k] + w * (target[k] - start[k])
            previous_length = length
            length = start_length + w * (length_target - start_length)
            remap_to_length(previous_length, length, friction, sliding, last_step, tension, last_tension_step)
            if quasi_static_step(u, length, rate_scale, params, effects, point_loads, friction, sliding,
                                 last_step, tension, last_tension_step, bend, compression, tip_tension,
                                 drive_tension, slack, points, frames, scalars, work, max_iterations,
                                 fraction <= smallest, fraction * dt_s, bend_rate, creep, not retry,
                                 fraction > tightening_smallest):
                done = w
                fraction = min(2.0 * fraction, 1.0 / n_sub)
                retry = False
            else:
                fraction *= 0.5
                retry = True    # in halves, and Newton starts at the last tensions
            if scalars[S_ITERATIONS] > stop_at_iterations:
                return t
        for k in range(4):
            applied_tendon_mm[k] = target[k]
        applied_insertion_mm[0] = length_target
        nb = points.shape[0] - 1
        for a in range(3):      # as the tracker sees it: p_tip + R_tip d + o
            tips_out[t, a] = points[nb, a] + (frames[nb, a, 0] * effects[E_SENSOR_X]
                                              + frames[nb, a, 1] * effects[E_SENSOR_X + 1]
                                              + frames[nb, a, 2] * effects[E_SENSOR_X + 2]) + effects[E_TRACKER_X + a]
        for k in range(4):
            drive_tension_out[t, k] = drive_tension[k]
    return n_samples
