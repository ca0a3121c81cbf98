"""Map element bends to 3D: constant curvature within each element (seed paper I.A).

Each lumped element i is a circular arc of length l_i whose bend vector b_i = (bx, by) [rad]
is expressed in the frame of the element's base. |b| is the angle the arc subtends and
b/|b| = (ux, uy) the direction it bends toward (bx > 0 bends toward +x, i.e. toward tendon 1).
The frames carry no twist. Base frame: origin at the centre of the support-tube exit,
z out of the tube, x toward tendon 1.
"""
import math

from model.jit import kernel


@kernel
def arc_transform(bx: float, by: float, length_mm: float, rot, offset) -> None:
    """Rotation and end point of one constant-curvature arc, in its base frame.

    With theta = |b| and (ux, uy) = b/theta, the arc rotates about the axis (-uy, ux, 0):

        R = [[c + (1-c) uy^2,  -(1-c) ux uy,    s ux],
             [-(1-c) ux uy,    c + (1-c) ux^2,  s uy],
             [-s ux,           -s uy,           c   ]],   c = cos(theta), s = sin(theta)

        end = (l/theta) * ((1-c) ux, (1-c) uy, s)

    (series expansions for theta -> 0). Writes R into `rot` (3x3) and the end into `offset` (3).
    """
    theta = math.sqrt(bx * bx + by * by)
    c = math.cos(theta)
    s = math.sin(theta)
    if theta < 1e-9:
        ux = 1.0
        uy = 0.0
        one_minus_c_over_theta = 0.5 * theta
        s_over_theta = 1.0
    else:
        ux = bx / theta
        uy = by / theta
        one_minus_c_over_theta = (1.0 - c) / theta
        s_over_theta = s / theta
    omc = 1.0 - c
    rot[0, 0] = c + omc * uy * uy
    rot[0, 1] = -omc * ux * uy
    rot[0, 2] = s * ux
    rot[1, 0] = -omc * ux * uy
    rot[1, 1] = c + omc * ux * ux
    rot[1, 2] = s * uy
    rot[2, 0] = -s * ux
    rot[2, 1] = -s * uy
    rot[2, 2] = c
    offset[0] = length_mm * one_minus_c_over_theta * ux
    offset[1] = length_mm * one_minus_c_over_theta * uy
    offset[2] = length_mm * s_over_theta


@kernel
def compose_backbone(bend_rad, length_mm, points_mm, frames) -> None:
    """Chain the element arcs from the base: p_{i+1} = p_i + R_i end_i, R_{i+1} = R_i R(b_i).

    bend_rad (N, 2), length_mm (N,) -> points_mm (N+1, 3), frames (N+1, 3, 3) with frames[i]
    the orientation at the base of element i (frames[N] at the tip).
    """
    n = bend_rad.shape[0]
    for a in range(3):
        points_mm[0, a] = 0.0
        for b in range(3):
            frames[0, a, b] = 1.0 if a == b else 0.0
    for i in range(n):
        # the arc's own rotation and end go into frames[i+1] and points[i+1] first, and are
        # then turned into the base frame in place, column by column (no scratch arrays: this
        # runs once per model step)
        local_rot = frames[i + 1]
        local_end = points_mm[i + 1]
        arc_transform(bend_rad[i, 0], bend_rad[i, 1], length_mm[i], local_rot, local_end)
        e0, e1, e2 = local_end[0], local_end[1], local_end[2]
        for a in range(3):
            points_mm[i + 1, a] = points_mm[i, a] + (frames[i, a, 0] * e0 + frames[i, a, 1] * e1 + frames[i, a, 2] * e2)
        for b in range(3):
            r0, r1, r2 = local_rot[0, b], local_rot[1, b], local_rot[2, b]
            for a in range(3):
                frames[i + 1, a, b] = frames[i, a, 0] * r0 + frames[i, a, 1] * r1 + frames[i, a, 2] * r2
