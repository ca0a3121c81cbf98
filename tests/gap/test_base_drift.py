"""The base model's drift (model.gap.base_drift): the stiffness ratios a fit can tell, against the
prior's. A common factor on EI, EA, sigma and Fsc is no drift (the tips cannot see it); an axially
soft catheter is."""
import pytest

from model import CatheterParams
from model.gap.base_drift import DRIFT_FACTOR, base_drift, describe_drift

PRIOR = CatheterParams.from_toml()


def scaled(factor, **ratios):
    """The prior with EI, EA, sigma and Fsc times `factor`, then X/EI times ratios[X]."""
    names = ("axial_stiffness_n", "sigma_n_per_mm2", "fsc_n_per_mm")
    return PRIOR.replace(bending_stiffness_nmm2=factor * PRIOR.bending_stiffness_nmm2,
                         **{name: factor * ratios.get(name, 1.0) * getattr(PRIOR, name) for name in names})


def test_a_common_factor_on_every_stiffness_is_no_drift():
    assert base_drift(PRIOR, scaled(4.3)) == []
    assert base_drift(PRIOR, scaled(0.2)) == []


def test_a_plant_of_the_priors_make_does_not_drift():
    assert base_drift(PRIOR, scaled(1.15, axial_stiffness_n=0.8, sigma_n_per_mm2=1.2, fsc_n_per_mm=0.85)) == []


def test_an_axially_soft_fit_is_named_with_its_factor():
    """As on the rod's soft proximal sheath: EA/EI at 1/21 of the prior's, on another force scale."""
    rows = base_drift(PRIOR, scaled(4.45, axial_stiffness_n=1 / 21))
    assert [row["ratio"] for row in rows] == ["EA/EI"]
    assert rows[0]["factor"] == pytest.approx(1 / 21)
    assert rows[0]["prior"] == pytest.approx(PRIOR.axial_stiffness_n / PRIOR.bending_stiffness_nmm2)
    sentence, = describe_drift(rows)
    assert sentence.startswith("the fit moved EA/EI (axial stiffness against bending) to 0.048x the prior's")


def test_the_limit_is_a_factor_either_way():
    assert base_drift(PRIOR, scaled(1.0, fsc_n_per_mm=0.99 * DRIFT_FACTOR)) == []
    assert [row["ratio"] for row in base_drift(PRIOR, scaled(1.0, fsc_n_per_mm=1.01 * DRIFT_FACTOR))] == ["Fsc/EI"]
    assert [row["ratio"] for row in base_drift(PRIOR, scaled(1.0, sigma_n_per_mm2=0.99 / DRIFT_FACTOR))] == ["sigma/EI"]
