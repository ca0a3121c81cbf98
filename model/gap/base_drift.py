"""Where the base model itself bent to fit: its stiffness ratios against the prior's.

The tips fix the Dahl model's EI, EA, sigma and Fsc only up to a common factor (a catheter twice as
stiff, pulled by tendons twice as tense, bends the same), so what a fit can tell are their ratios to
the bending stiffness:

    EA / EI      axial against bending stiffness (1/mm^2)
    sigma / EI   Dahl stiffness against bending stiffness (1/mm^4)
    Fsc / EI     constant friction against bending stiffness (1/mm^3)

A fitted ratio more than DRIFT_FACTOR from the prior's means the baseline took up something the
prior's catheter does not have. On the rod plant a soft proximal sheath (the rod's lumen
compression) left no held-out error above that of clean cases; the baseline had absorbed it with
an EA/EI 20-27 times below the prior's (README, "Sim-to-real gap diagnosis"). A prior
that describes another device altogether (a real robot measured against the default catheter)
drifts too; the report then says that the prior does not describe it.
"""
from __future__ import annotations

from model.params import CatheterParams

DRIFT_FACTOR = 3.0     # a catheter of the prior's make is known better than this; the plants differ by 10-20 %
RATIOS = (("axial_stiffness_n", "EA/EI", "axial stiffness"),
          ("sigma_n_per_mm2", "sigma/EI", "Dahl stiffness"),
          ("fsc_n_per_mm", "Fsc/EI", "constant friction"))


def base_drift(prior: CatheterParams, fitted: CatheterParams) -> list[dict]:
    """Each ratio X/EI of `fitted` more than DRIFT_FACTOR above or below the prior's:
    {"ratio", "prior", "fitted", "factor"} with factor = fitted / prior."""
    rows = []
    for name, ratio, _ in RATIOS:
        before = getattr(prior, name) / prior.bending_stiffness_nmm2
        after = getattr(fitted, name) / fitted.bending_stiffness_nmm2
        if before > 0.0 and after > 0.0 and not 1.0 / DRIFT_FACTOR <= after / before <= DRIFT_FACTOR:
            rows.append({"ratio": ratio, "prior": before, "fitted": after, "factor": after / before})
    return rows


def describe_drift(rows: list[dict]) -> list[str]:
    """One sentence per drifted ratio, for the residual's description."""
    names = {ratio: what for _, ratio, what in RATIOS}
    return [f"the fit moved {row['ratio']} ({names[row['ratio']]} against bending) to {row['factor']:.2g}x the "
            f"prior's ({row['fitted']:.3g} against {row['prior']:.3g}): the base model took up something the "
            "prior's catheter lacks" for row in rows]
