"""Why a blind case above the detection limit was missed: three causes, each mended elsewhere.

A single-effect case above the detection limit (`crest.gap.blind_benchmark`) whose verdict does not
name its true effect is put down to the first of these that holds:

- `absorbed`: the calibrated base model takes the effect up. Its visible part (`crest.gap.visible_effect`:
  what the base model, calibrated on the held-out log itself, cannot absorb) is below the detection
  limit, so no verdict drawn from these logs could name it. Known on the rod family only; a Dahl
  case never gets this cause.
- `oracle_not_significant`: the true catalog effect, fitted as the diagnosis fits a candidate (the
  case's oracle), removes no significant error on the report half of the held-out log. With the
  report half's baseline RMSE b and the oracle shrink s, the test is `model.gap.significance.
  is_meaningful(b, b (1 - s), sigma)` with sigma = f / sqrt(3) from the case's noise floor f: the
  same test the diagnosis puts to a candidate on the selection half. The catalog's form of the effect
  does not reach what the plant did (on the rod family: another physics), or the logs hold too
  little of it.
- `diagnosis`: the oracle removes significant error, yet the verdict named another effect or
  nothing (or the diagnosis gave no result): the diagnosis's own miss, the one its rules can mend.

A case whose oracle failed or was never computed gets `no_oracle`.

Apart from its cause, a miss whose verdict listed the true effect as good on these logs (the
verdict's `as_good`, kept in the case row since ff8ba06) is a tie the logs cannot break: the
diagnosis found the truth and could not tell it from the effect it named. `miss_causes` counts them
as `truth_as_good`.
"""
from __future__ import annotations

import math

from model.gap.significance import is_meaningful

ABSORBED = "absorbed"
ORACLE_NOT_SIGNIFICANT = "oracle_not_significant"
DIAGNOSIS = "diagnosis"
NO_ORACLE = "no_oracle"
CAUSES = (ABSORBED, ORACLE_NOT_SIGNIFICANT, DIAGNOSIS, NO_ORACLE)
CAUSE_WORDS = {ABSORBED: "absorbed by the calibrated base model (below the visible limit)",
               ORACLE_NOT_SIGNIFICANT: "the true catalog effect, fitted, removes nothing significant",
               DIAGNOSIS: "the diagnosis's own (the fitted true effect removes significant error)",
               NO_ORACLE: "no oracle"}


def miss_cause(row: dict) -> str:
    """The cause of one missed case's miss (see module doc); `row` is a blind-benchmark case row."""
    if "no_result" in row:
        return DIAGNOSIS
    if "visible_relative_size" in row and not row.get("above_visible_limit", False):
        return ABSORBED
    oracle = row.get("oracle_shrink")
    if oracle is None or not math.isfinite(oracle):
        return NO_ORACLE
    before_mm = row["holdout_rmse_before_mm"]
    sigma_mm = row["noise_floor_mm"] / math.sqrt(3.0) if row.get("noise_floor_mm") is not None else None
    return DIAGNOSIS if is_meaningful(before_mm, before_mm * (1.0 - oracle), sigma_mm) else ORACLE_NOT_SIGNIFICANT


def miss_causes(missed: list[dict]) -> dict:
    """{cause: count} over every cause, "by_effect": {true effect: {cause: count}} over the causes met, and
    "truth_as_good": the misses whose verdict listed the true effect as good (see module doc)."""
    causes = [(row["truth"][0], miss_cause(row)) for row in missed]
    by_effect: dict[str, dict[str, int]] = {}
    for effect_id, cause in sorted(causes):
        by_effect.setdefault(effect_id, {})
        by_effect[effect_id][cause] = by_effect[effect_id].get(cause, 0) + 1
    return {**{cause: sum(c == cause for _, c in causes) for cause in CAUSES}, "by_effect": by_effect,
            "truth_as_good": sum(row["truth"][0] in row.get("as_good", []) for row in missed)}
