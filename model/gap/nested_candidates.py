"""Between two found effects where one is a limit of the other, name the simpler one.

Some catalog effects hold another as a limit of their parameters (`CandidateEffect.reduces_to`):
a viscoelastic drive line, s + tau ds/dt = c T, is an elastic one, s = c T, as tau -> 0. Fitted
to a plant with the simpler effect, the richer one reaches at least as low an error with its extra
freedom, and can outrank it by a few per cent. On rod seed 71, case 8 (an elastic drive line of
0.045 mm/N), `rate_lag` (tau 0.051 s, at the edge of what the fits' 10 Hz resolve) reached 0.589 mm
on the selection half and `tendon_elasticity` 0.605 mm (baseline 0.914 mm): the lag was named.

So when the best found candidate reduces to a simpler one that is found too, the simpler one leads
unless going from it to the richer one removes more error than noise and fitting freedom explain
(`significance.is_meaningful`, on the selection half). A true lag keeps its verdict: on dahl seed
53, case 4 (tau 0.137 s), 0.537 of the error removed against the elastic line's 0.183.
"""
from __future__ import annotations

from collections.abc import Sequence

from model.effects.catalog import effect
from model.gap.candidates import CandidateResult
from model.gap.significance import is_meaningful


def simplest_sufficient(eligible: Sequence[CandidateResult], noise_mm: float | None) -> list[CandidateResult]:
    """`eligible` (found singles, best first) with the simpler effect the best reduces to moved to the
    front, where it is found too and the best is not meaningfully better than it (see module doc)."""
    ranked = list(eligible)
    if not ranked:
        return ranked
    best = ranked[0]
    simpler_id = effect(best.effects[0]).reduces_to
    simpler = next((r for r in ranked if r.effects == (simpler_id,)), None)
    if simpler is None or is_meaningful(simpler.holdout_rmse_mm, best.holdout_rmse_mm, noise_mm):
        return ranked
    return [simpler] + [r for r in ranked if r is not simpler]
