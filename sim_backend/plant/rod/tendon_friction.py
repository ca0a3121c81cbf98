"""Distributed Coulomb friction between a tendon and its lumen, with memory (return mapping).

A tendon under tension T pressed around a bend of curvature kappa loads its lumen with a normal
force T |kappa| per mm, plus a constant interference load; Coulomb friction then bounds the
tension gradient along the lumen:

    |dT/ds| <= mu * |kappa| * T + c0          (capstan law, c0: constant friction per mm, N/mm)

Where the tendon slides toward the drive (pulling) the bound is met with dT/ds < 0; where it
slides back (releasing) with dT/ds > 0; over a sliding region of wrap angle theta with c0 = 0,
T_distal / T_proximal = exp(-mu theta) (pulling) or exp(+mu theta) (releasing). Where it sticks,
the tendon does not move in its lumen and its tension keeps the value it had (the memory).

Across a segment of wrap angle theta the exact solution of dT/ds = -+(mu kappa T + c0) gives
the admissible interval for the distal tension (c0 lumped at the segment's proximal end):

    lo = T_prox * exp(-mu theta) - c0 h,   hi = T_prox * exp(+mu theta) + c0 h

and the return mapping is: trial = the tendon's previous tension there (stick), clamped to
[lo, hi] (slip where the trial lies outside). A tension cannot go below zero.
"""
from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def clamp_to_capstan(trial_n: float, proximal_n: float, proximal_sensitivity: float, mu: float,
                     wrap_rad: float, wrap_per_n: float, c0_h_n: float) -> tuple[float, float]:
    """(tension, sensitivity) at the distal node of a segment.

    sensitivity S = dT / dT_drive along the tendon: zero where the tendon sticks (its tension is
    the memory); through a slipping segment, differentiating T = T_p exp(+-mu theta) -+ c0 h with
    the wrap theta itself growing with the tendon's own tension (wrap_per_n = d theta / d T_p):

        S = S_p exp(+-mu theta) (1 +- mu T_p wrap_per_n)
    """
    grow = math.exp(mu * wrap_rad)
    hi = proximal_n * grow + c0_h_n
    if trial_n > hi:
        return hi, proximal_sensitivity * grow * (1.0 + mu * proximal_n * wrap_per_n)
    lo = proximal_n / grow - c0_h_n
    if trial_n < lo:
        return lo, proximal_sensitivity / grow * (1.0 - mu * proximal_n * wrap_per_n)
    return trial_n, 0.0
