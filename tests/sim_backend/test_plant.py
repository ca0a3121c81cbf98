"""The plant behind the drives: the default Dahl plant, effects from config, the --plant loader."""
import numpy as np
import pytest

from model import CatheterParams, ConstantCurvature, tendons_from_articulation
from sim_backend.plant import (DahlPlant, PlantConfig, PlantConfigError, PlantError, PlantLoadError, PlantRunner,
                               load_plant)


class NotAPlant:
    def reset(self):
        pass


class NaNPlant:
    def reset(self):
        pass

    def step(self, dt_s, tendon_mm, insertion_mm):
        return np.full(3, np.nan), np.zeros(4)


def test_default_plant_is_the_dahl_catheter_with_no_effects_and_10_to_20_percent_mismatch():
    config = PlantConfig.from_toml()
    model = CatheterParams.from_toml()
    assert config.effects == {}
    assert config.params.mu == pytest.approx(1.15 * model.mu)
    assert config.params.bending_stiffness_nmm2 == pytest.approx(0.9 * model.bending_stiffness_nmm2)
    assert config.params.tendon_offset_mm == model.tendon_offset_mm


def test_default_plant_bends_toward_pulled_tendon_and_reports_tension():
    plant = load_plant("sim_backend.plant:DahlPlant")
    plant.reset()
    u = tendons_from_articulation(np.pi / 2, 0.0, 2.5, 0.02)
    tip, tension = plant.step(0.01, u, 80.0)
    assert tip[0] > 40.0 and tension[0] > tension[2]


def test_effect_switched_on_changes_the_plant():
    u = tendons_from_articulation(np.pi / 2, np.pi / 6, 2.5, 0.02)
    base = DahlPlant(PlantConfig.from_toml())
    twisted = DahlPlant(PlantConfig.from_toml().with_effects({"torsion": {"twist_rad": 0.3}}))
    tip_base, _ = base.step(0.01, u, 80.0)
    tip_twisted, _ = twisted.step(0.01, u, 80.0)
    plane = np.degrees(np.arctan2(tip_twisted[1], tip_twisted[0]) - np.arctan2(tip_base[1], tip_base[0]))
    assert abs(plane) > 5.0


def test_frictionless_plant_matches_constant_curvature(tmp_path):
    params = CatheterParams().frictionless()
    plant = DahlPlant(PlantConfig(params=params))
    u = tendons_from_articulation(np.pi, 0.0, params.tendon_offset_mm)
    tip, _ = plant.step(0.01, u, 70.0)
    assert np.linalg.norm(tip - ConstantCurvature(params).tip_mm(u, 70.0)) < 0.7


@pytest.mark.parametrize("spec,match", [("nocolon", "expected"), ("no_such_module_xyz:P", "cannot import"),
                                        ("sim_backend.plant:Missing", "has no"),
                                        ("tests.sim_backend.test_plant:NotAPlant", "needs reset")])
def test_bad_plant_spec_gives_clear_error(spec, match):
    with pytest.raises(PlantLoadError, match=match):
        load_plant(spec)


def test_runner_rejects_a_plant_output_that_is_not_finite():
    with pytest.raises(PlantError, match="non-finite"):
        PlantRunner(NaNPlant(), np.zeros(4), 80.0)


@pytest.mark.parametrize("text,match", [
    ('[effects]\nbacklash = { width_mm = -1.0 }\n', "width_mm"),
    ('[effects]\nfriction_monster = {}\n', "unknown effect"),
    ('[mismatch]\nmu = "high"\n', "mu"),
    ('[tracker]\ndropout = 1.5\n', "dropout"),
])
def test_bad_plant_config_names_the_field(tmp_path, text, match):
    (tmp_path / "catheter.toml").write_text("")
    path = tmp_path / "plant.toml"
    path.write_text(text)
    with pytest.raises(PlantConfigError, match=match):
        PlantConfig.from_toml(path)
