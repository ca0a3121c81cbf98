"""Where a fit starts: the base model at a few friction coefficients; a candidate effect switched
off, or at cheap probe values.

A fit of a nonsmooth, history-dependent model stalls easily far from the optimum. One model
run at each of a few probe values of an effect is much cheaper than a fit, and picks a start
in the right basin (e.g. gravity in the right direction).

A one-sided effect is probed in octaves of its typical value down to 1/16 of it,

    v_j = off + 2^-j (typical - off),   j = 4, 3, 2, 1, 0,

since the effects a catheter has span decades (the blind benchmark draws them log-uniformly from
about 1/20 of the typical value). Probed only at 1/4, 1/2 and 1, a small effect started from 'off'
and its fit stalled there: dahl seed 91's creep of 0.13 of the typical compliance removed nothing
(oracle 0.56 of the report half's error); probed down to 1/16 it removed 0.50 of the selection
half's.
"""
from __future__ import annotations

import numpy as np

from model.effects.catalog import effect
from model.params import CatheterParams

MU_START_FACTORS = (0.5, 1.0, 1.75)
GRID_FACTORS = (0.6, 1.0, 1.6)    # EI, and mu and Fsc, of `base_grid` relative to the prior
ONE_SIDED_FRACTIONS = (1 / 16, 1 / 8, 1 / 4, 1 / 2, 1.0)   # of the typical value: a one-sided effect's probes


def base_starts(prior: CatheterParams) -> list[CatheterParams]:
    """The prior with its friction coefficient mu at 1/2, 1 and 7/4 of its value.

    EI and mu trade off (friction is proportional to mu * tension, and the tension to EI), and
    from the prior alone a fit of noiseless data stalled at mu 0.19 of a true 0.26, behind a
    ridge, while fits from 0.1 and 0.35 reached it.
    """
    return [prior.replace(mu=factor * prior.mu) for factor in MU_START_FACTORS]


def base_grid(prior: CatheterParams) -> list[CatheterParams]:
    """The prior with EI, mu and Fsc each at GRID_FACTORS of its value: 27 catheters, worth one model run each.

    A catheter whose stiffness is far from the prior's (a real catheter, or one from another
    batch) can sit behind a ridge from all of `base_starts`: one of them fitted a clean recording
    to 1.06 mm where a fit from EI 0.6x reached the 0.17 mm noise floor.
    """
    return [prior.replace(bending_stiffness_nmm2=ei * prior.bending_stiffness_nmm2, mu=mu * prior.mu,
                          fsc_n_per_mm=fsc * prior.fsc_n_per_mm)
            for ei in GRID_FACTORS for mu in GRID_FACTORS for fsc in GRID_FACTORS]


def start_values(effect_id: str) -> tuple[float, ...]:
    """The candidate switched off: 0 where 0 is in range, else its typical value."""
    candidate = effect(effect_id)
    return tuple(0.0 if low <= 0.0 <= high else typ
                 for typ, low, high in zip(candidate.typical, candidate.lower, candidate.upper))


def probe_values(effect_id: str) -> list[tuple[float, ...]]:
    """Starting points worth one model run each.

    Off, then: one-sided effects at 1/16, 1/8, 1/4, 1/2 and all of their typical values; a signed single
    parameter at -+1/2 and -+1 typical; signed vectors (directions) at the typical magnitude
    (and half of it for two parameters) in eight directions of the plane of their first two
    parameters, and -+ along the third.
    """
    candidate = effect(effect_id)
    off = start_values(effect_id)
    typical = np.asarray(candidate.typical, dtype=float)
    if min(candidate.lower) >= 0:
        return [off] + [tuple(o + f * (t - o) for o, t in zip(off, typical)) for f in ONE_SIDED_FRACTIONS]
    magnitude = float(np.linalg.norm(typical))
    if len(off) == 1:
        vectors = [np.array([f * s * magnitude]) for f in (0.5, 1.0) for s in (1.0, -1.0)]
    else:
        fractions = (1.0,) if len(off) == 3 else (0.5, 1.0)
        angles = np.radians(np.arange(0, 360, 45))
        vectors = [np.r_[f * magnitude * np.cos(a), f * magnitude * np.sin(a), np.zeros(len(off) - 2)]
                   for f in fractions for a in angles]
        if len(off) == 3:
            vectors += [np.array([0.0, 0.0, s * magnitude]) for s in (1.0, -1.0)]
    low, high = np.asarray(candidate.lower), np.asarray(candidate.upper)
    return [off] + [tuple(float(v) for v in np.clip(vector, low, high)) for vector in vectors]
