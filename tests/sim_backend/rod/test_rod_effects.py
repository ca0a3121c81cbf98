"""Every effect of the rod plant moves the tip, in a run that exercises what it acts on."""
from __future__ import annotations

import numpy as np
import pytest

from rod_scenarios import DT_S, description, pull
from sim_backend.plant.rod import ROD_EFFECTS, RodPlant


def _history():
    """Insertion in and out at rest, a pull to ~120 deg, a 3 s hold, a partial release."""
    rows = [(0.0, length) for length in np.linspace(80.0, 90.0, 100)]
    rows += [(0.0, length) for length in np.linspace(90.0, 80.0, 100)]
    rows += [(u, 80.0) for u in np.linspace(0.0, 5.0, 100)]
    rows += [(5.0, 80.0)] * 300
    rows += [(u, 80.0) for u in np.linspace(5.0, 2.5, 100)]
    return rows


def _tips(effects: dict) -> np.ndarray:
    plant = RodPlant(description(effects=effects))
    return np.array([plant.step(DT_S, [u, 0.0, -u, 0.0], length)[0] for u, length in _history()])


@pytest.fixture(scope="module")
def clean_tips() -> np.ndarray:
    return _tips({})


@pytest.mark.parametrize("effect_id", list(ROD_EFFECTS))
def test_each_effect_at_its_typical_value_moves_the_tip(effect_id, clean_tips):
    shift_mm = np.linalg.norm(_tips({effect_id: {}}) - clean_tips, axis=1)
    assert shift_mm.max() > 0.3, f"{effect_id} moved the tip by at most {shift_mm.max():.3f} mm"


def test_the_out_of_catalog_effects_are_there():
    assert {e.id for e in ROD_EFFECTS.values() if not e.in_catalog} == {"sheath_creep", "sheath_compression",
                                                                        "lumen_offset_drift", "stiffness_step"}


def test_creep_keeps_bending_during_a_hold():
    plant = RodPlant(description(effects={"sheath_creep": {"creep_fraction": 0.2, "time_constant_s": 2.0}}))
    for u in np.linspace(0.0, 4.0, 50):
        plant.step(DT_S, [u, 0.0, -u, 0.0], 80.0)
    start, _ = plant.step(DT_S, [4.0, 0.0, -4.0, 0.0], 80.0)
    for _ in range(500):
        end, _ = plant.step(DT_S, [4.0, 0.0, -4.0, 0.0], 80.0)
    assert np.linalg.norm(end - start) > 0.3      # the tip drifts at a constant drive input


def test_the_sensor_offset_turns_with_the_tip_and_the_tracker_offset_does_not():
    offset = {"sensor_x_mm": 0.0, "sensor_y_mm": 0.0, "sensor_z_mm": 2.0}
    registration = {"registration_x_mm": 1.0, "registration_y_mm": -0.5, "registration_z_mm": 0.25}
    plain, mounted = RodPlant(description()), RodPlant(description(effects={"sensor_offset": offset}))
    registered = RodPlant(description(effects={"tracker_offset": registration}))
    for u in np.linspace(0.0, 5.0, 50):
        tip, _ = plain.step(DT_S, [u, 0.0, -u, 0.0], 80.0)
        sensor, _ = mounted.step(DT_S, [u, 0.0, -u, 0.0], 80.0)
        shifted, _ = registered.step(DT_S, [u, 0.0, -u, 0.0], 80.0)
        assert np.allclose(shifted - tip, (1.0, -0.5, 0.25), atol=1e-9)
    assert np.allclose(sensor - tip, 2.0 * plain.rotation[-1][:, 2], atol=1e-9)
    assert plain.rotation[-1][0, 2] > 0.5      # bent far enough that the two differ


def test_lumen_compression_takes_the_arm_the_tendon_load_pushes_in_and_straightens_the_base():
    """Within the soft wall the moment arm is r^2 / (r + c_r T) (the tension's own load pushes the
    lumen in): the base curvature is sum_k T_k a_k / EI, below the plain rod's, and the more so the
    harder the pull; under displacement control the lost bend reappears distally."""
    wall = {"radial_compliance_mm_per_n": 0.04, "soft_wall_length_mm": 20.0}
    plain, soft = RodPlant(description()), RodPlant(description(effects={"lumen_compression": wall}))
    r_mm, ei_nmm2 = soft.description.tendon_offset_mm, soft.description.bending_stiffness_nmm2
    base_ratio = []
    for start_mm, stop_mm in ((0.0, 2.5), (2.5, 5.0)):
        for u in np.linspace(start_mm, stop_mm, 50):
            pull(plain, u)
            pull(soft, u)
        arm_mm = r_mm ** 2 / (r_mm + wall["radial_compliance_mm_per_n"] * soft.tension_n[0])
        moment = soft.tension_n[0] * arm_mm
        assert np.hypot(*soft.kappa_per_mm[0]) == pytest.approx(abs(moment[0] - moment[2]) / ei_nmm2, rel=1e-9)
        base_ratio.append(np.hypot(*soft.kappa_per_mm[0]) / np.hypot(*plain.kappa_per_mm[0]))
    assert base_ratio[1] < base_ratio[0] < 1.0
    assert np.hypot(*soft.kappa_per_mm[-1]) > np.hypot(*plain.kappa_per_mm[-1])

