"""How much of the gap a named verdict explains: `confident` or `partial`.

The verdict names an effect only if it passes the significance and plausibility tests on the
selection half. Passing says the effect removes more error than noise and fitting freedom
explain; it does not say the effect is the gap. On a catheter that is not the model, a catalog
effect can take up part of an error whose cause is outside the catalog. The grade tells a reader
which case they are likely in, from the held-out tip RMSE on the report half (the half the
verdict was not chosen on) before and after the effect, against the tracker's noise floor f
(sqrt(3) sigma, which no model removes):

    gap(e) = sqrt(max(e^2 - f^2, 0))                the error above the noise floor
    explained = 1 - gap(e_after) / gap(e_before)    (0 where gap(e_before) = 0)
    confident   if explained >= CONFIDENT_SHARE     the effect at least halves the gap: it is most of it
    partial     otherwise                           most of the gap stays: model form, an effect
                                                    outside the catalog, or this effect only in part

Without a known noise level f = 0, and `explained` is the shrink itself. `none` and `unexplained`
name nothing and have no grade. A pair is graded on its joint errors.
"""
from __future__ import annotations

import math

CONFIDENT = "confident"
PARTIAL = "partial"
CONFIDENT_SHARE = 0.5


def gap_mm(error_mm: float, noise_floor_mm: float | None) -> float:
    """gap(e) = sqrt(max(e^2 - f^2, 0)): the error above the noise floor (f = 0 when unknown)."""
    return math.sqrt(max(error_mm ** 2 - (noise_floor_mm or 0.0) ** 2, 0.0))


def explained_share(before_mm: float, after_mm: float, noise_floor_mm: float | None) -> float:
    """The share of the held-out error above the noise floor that the verdict removes (see module doc)."""
    gap_before = gap_mm(before_mm, noise_floor_mm)
    return 1.0 - gap_mm(after_mm, noise_floor_mm) / gap_before if gap_before > 0 else 0.0


def confidence(effects: list[str], before_mm: float, after_mm: float, noise_floor_mm: float | None) -> str | None:
    """The grade of a verdict naming `effects` (empty: `none` or `unexplained`, no grade) whose report-half
    tip RMSE goes from before_mm to after_mm, against the tracker's noise floor (None: unknown)."""
    if not effects:
        return None
    return CONFIDENT if explained_share(before_mm, after_mm, noise_floor_mm) >= CONFIDENT_SHARE else PARTIAL


def confidence_line(effects: list[str], before_mm: float, after_mm: float, noise_floor_mm: float | None) -> str | None:
    """One sentence for the verdict's reader: the grade, the share of the gap removed and what stays."""
    grade = confidence(effects, before_mm, after_mm, noise_floor_mm)
    if grade is None:
        return None
    share = explained_share(before_mm, after_mm, noise_floor_mm)
    floor = "" if noise_floor_mm is None else f" above the {noise_floor_mm:.3f} mm noise floor"
    named, error = " + ".join(effects), f"the held-out error{floor} on the report half"
    said = f"{named} removes {100 * share:.0f} % of {error}" if share >= 0.0 else \
        f"{named} makes {error} {-100 * share:.0f} % larger (it was selected on the other half)"
    said += f" ({100 * CONFIDENT_SHARE:.0f} % makes a verdict confident)"
    if grade == CONFIDENT:
        return f"confident: {said}: most of the gap"
    stays = "most of it" if share >= 0.0 else "all of it"
    return (f"partial: {said}: {gap_mm(after_mm, noise_floor_mm):.3f} mm RMS of the gap stays, {stays}; model form, an "
            "effect outside the catalog, or this effect only in part")
