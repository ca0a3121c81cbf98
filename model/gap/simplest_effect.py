"""Between found effects that explain the error about as well, name the one with fewer parameters.

A richer effect fitted to a plant with a simpler one reaches at least as low an error with its extra
freedom, and can outrank it by a few per cent:

- a viscoelastic drive line, s + tau ds/dt = c T, is an elastic one, s = c T, as tau -> 0. On rod
  seed 71, case 8 (an elastic drive line of 0.045 mm/N), `rate_lag` (tau 0.051 s, at the edge of
  what the fits' 10 Hz resolve) reached 0.589 mm on the selection half and `tendon_elasticity`
  0.605 mm (baseline 0.914 mm): the lag was named;
- a sensor offset along the tip's axis (three parameters) shifts the tip as a constant error of
  the free length does, which is most of what the support tube's play (one) leaves. On rod seeds
  70, 77 and 82 a tube friction was named `sensor_offset` that way (0.211 of the selection half's
  error against the tube friction's 0.196 on seed 82, case 17).

So the found effects with fewer free parameters than the best one, where going from their error to
the best's removes no more than noise and fitting freedom explain (`significance.is_meaningful`, on
the selection half), are sufficient, and the simplest of them leads (the fewest parameters, then the
lowest error). A richer effect that removes meaningfully more keeps its verdict: on dahl seed 53,
case 4, a true lag (tau 0.137 s) removed 0.537 of the error against the elastic line's 0.183.

The other found effects that the named one does not beat by more than noise and fitting freedom
explain are as good on these logs (`as_good_as`): the verdict lists them beside it, since the logs
cannot tell them apart. The two rigid offsets are such twins where the tip barely
turns: on rod seed 112 a tracker offset was named `sensor_offset` (1.061 mm on the selection half
against the tracker offset's 1.079 mm, from 1.837 mm) and a sensor offset `tracker_offset`.
"""
from __future__ import annotations

from collections.abc import Sequence

from model.effects.catalog import effect
from model.gap.candidates import CandidateResult
from model.gap.significance import is_meaningful


def parameter_count(result: CandidateResult) -> int:
    """Free parameters of a single candidate's effect."""
    return len(effect(result.effects[0]).param_names)


def simplest_sufficient(eligible: Sequence[CandidateResult], noise_mm: float | None) -> list[CandidateResult]:
    """`eligible` (found singles, best first) with the simplest sufficient effect moved to the front
    (see module doc); unchanged where no found effect with fewer parameters is sufficient."""
    ranked = list(eligible)
    if not ranked:
        return ranked
    best = ranked[0]
    sufficient = [r for r in ranked[1:] if parameter_count(r) < parameter_count(best)
                  and not is_meaningful(r.holdout_rmse_mm, best.holdout_rmse_mm, noise_mm)]
    if not sufficient:
        return ranked
    simplest = min(sufficient, key=lambda r: (parameter_count(r), r.holdout_rmse_mm))
    return [simplest] + [r for r in ranked if r is not simplest]


def as_good_as(named: CandidateResult, found: Sequence[CandidateResult],
               noise_mm: float | None) -> list[CandidateResult]:
    """The effects of `found` (other than `named`) that `named` does not beat on the selection half by
    more than noise and fitting freedom explain (`significance.is_meaningful`), best first."""
    return [r for r in found if r.effects != named.effects
            and not is_meaningful(r.holdout_rmse_mm, named.holdout_rmse_mm, noise_mm)]
