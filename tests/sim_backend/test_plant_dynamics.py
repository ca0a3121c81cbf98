"""The virtual plant's [dynamics] table: the catheter's dampers and masses switched on from its TOML."""
import numpy as np
import pytest

from model import tendons_from_articulation
from sim_backend.plant import DahlPlant, PlantConfig, PlantConfigError


def plant_toml(tmp_path, dynamics: str):
    (tmp_path / "catheter.toml").write_text("")
    path = tmp_path / "plant.toml"
    path.write_text(dynamics)
    return path


def test_dynamics_table_makes_the_plant_lag_a_step(tmp_path):
    """A damped plant reaches the quasi-static tip only after its damping time, without overshoot."""
    quasi_static = DahlPlant(PlantConfig.from_toml(plant_toml(tmp_path, "")))
    dynamic_config = PlantConfig.from_toml(plant_toml(tmp_path, "[dynamics]\ndamping_time_s = 0.5\n"))
    assert dynamic_config.params.damping_time_s == 0.5 and dynamic_config.params.inertia_scale == 0.0
    dynamic = DahlPlant(dynamic_config)
    # tip load on a catheter with its tendons paid out: the step response of the damped shaft
    for plant in (quasi_static, dynamic):
        plant.model.set_point_forces([[0.02, 0.0, 0.0]])
    slack = np.full(4, -1.0)
    settled = [quasi_static.step(0.01, slack, 80.0)[0][0] for _ in range(3)][-1]
    tips = np.array([dynamic.step(0.01, slack, 80.0)[0][0] for _ in range(300)])
    assert tips[0] < 0.1 * settled
    assert np.all(np.diff(tips) >= -1e-9)
    assert tips[-1] == pytest.approx(settled, rel=0.01)


def test_dynamic_plant_follows_an_articulation(tmp_path):
    plant = DahlPlant(PlantConfig.from_toml(plant_toml(tmp_path, "[dynamics]\ndamping_time_s = 0.02\n"
                                                                 "inertia_scale = 1.0\n")))
    u = tendons_from_articulation(np.pi / 2, 0.0, 2.5, 0.02)
    for t in np.linspace(0.0, 1.0, 100):
        tip, tension = plant.step(0.01, t * u, 80.0)
    assert tip[0] > 40.0 and tension[0] > tension[2]


@pytest.mark.parametrize("text,match", [
    ('[dynamics]\ndamping_time_s = -0.1\n', "damping_time_s"),
    ('[dynamics]\nmass_kg = 1.0\n', "unknown key"),
    ('[dynamics]\ninertia_scale = "heavy"\n', "inertia_scale"),
])
def test_bad_dynamics_table_names_the_field(tmp_path, text, match):
    with pytest.raises(PlantConfigError, match=match):
        PlantConfig.from_toml(plant_toml(tmp_path, text))
