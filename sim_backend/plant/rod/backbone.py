"""Kirchhoff backbone of the rod plant: a segment's rotation and displacement, and the weight's moment.

Frame convention: R(s) maps body to base coordinates, its third column is the tangent e3(s);
body x points toward tendon 1 at s = 0. A bending-curvature vector kappa = (kx, ky, 0) (1/mm,
body frame) turns the frame as dR/ds = R [kappa]x, so ky > 0 bends the tangent toward body +x.

Over one segment of material length h the curvature is taken constant (the mean of its two
nodes), which makes the segment an exact circular arc: no integration error for piecewise
constant curvature, so a uniformly bent rod comes out exactly on its constant-curvature arc.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def segment_rotation(kx: float, ky: float, h_mm: float, out: np.ndarray) -> None:
    """Rotation over a segment of length h with constant curvature (kx, ky, 0): Rodrigues' formula

        Q = I + sin(th) [n]x + (1 - cos(th)) [n]x^2,   th = |kappa| h,  n = kappa / |kappa|.
    """
    k = math.hypot(kx, ky)
    th = k * h_mm
    if th < 1e-12:
        nx, ny, s, c1 = 0.0, 0.0, 0.0, 0.0
    else:
        nx, ny, s, c1 = kx / k, ky / k, math.sin(th), 1.0 - math.cos(th)
    # [n]x for n = (nx, ny, 0); [n]x^2 = n n^T - I
    out[0, 0] = 1.0 + c1 * (nx * nx - 1.0)
    out[0, 1] = c1 * nx * ny
    out[0, 2] = s * ny
    out[1, 0] = c1 * nx * ny
    out[1, 1] = 1.0 + c1 * (ny * ny - 1.0)
    out[1, 2] = -s * nx
    out[2, 0] = -s * ny
    out[2, 1] = s * nx
    out[2, 2] = 1.0 - c1


@njit(cache=True)
def segment_displacement(kx: float, ky: float, h_mm: float, stretch: float, out: np.ndarray) -> None:
    """Chord of the arc, in the segment's start frame [mm]:

        d = stretch * h * [ (1 - cos th)/th * (n x e3) + sin(th)/th * e3 ],   n x e3 = (ny, -nx, 0),

    with th = |kappa| h (the bend angle of the material segment) and stretch = 1 + axial strain.
    """
    k = math.hypot(kx, ky)
    th = k * h_mm
    length = stretch * h_mm
    if th < 1e-8:
        # series: (1 - cos th)/th ~ th/2, sin th / th ~ 1 - th^2/6
        out[0] = length * 0.5 * h_mm * ky
        out[1] = -length * 0.5 * h_mm * kx
        out[2] = length * (1.0 - th * th / 6.0)
        return
    a = (1.0 - math.cos(th)) / th
    out[0] = length * a * ky / k
    out[1] = -length * a * kx / k
    out[2] = length * math.sin(th) / th


@njit(cache=True)
def weight_moments_body(position_mm: np.ndarray, rotation: np.ndarray, weight_n: np.ndarray,
                        out: np.ndarray) -> None:
    """Bending moment of the rod's own weight at each node, body frame (N*mm), x and y components.

    The internal moment at node i balances the weight of everything distal of it:

        m(s_i) = sum_{j > i} (p_j - p_i) x W_j = S_pw(i) - p_i x S_w(i),
        S_w(i) = sum_{j > i} W_j,  S_pw(i) = sum_{j > i} p_j x W_j,

    with W_j the weight lumped at node j (N, base frame); both sums run once from the tip, O(M).
    The body-frame moment is R_i^T m(s_i); its z part (torsion) is dropped: the rod is torsionally rigid.
    """
    n = position_mm.shape[0]
    swx = swy = swz = 0.0
    spx = spy = spz = 0.0
    for i in range(n - 1, -1, -1):
        px, py, pz = position_mm[i, 0], position_mm[i, 1], position_mm[i, 2]
        mx = spx - (py * swz - pz * swy)
        my = spy - (pz * swx - px * swz)
        mz = spz - (px * swy - py * swx)
        out[i, 0] = rotation[i, 0, 0] * mx + rotation[i, 1, 0] * my + rotation[i, 2, 0] * mz
        out[i, 1] = rotation[i, 0, 1] * mx + rotation[i, 1, 1] * my + rotation[i, 2, 1] * mz
        wx, wy, wz = weight_n[i, 0], weight_n[i, 1], weight_n[i, 2]
        swx += wx
        swy += wy
        swz += wz
        spx += py * wz - pz * wy
        spy += pz * wx - px * wz
        spz += px * wy - py * wx
