"""The rod plant's description file and effect parameters: bad input gets a clear error."""
from __future__ import annotations

import math

import pytest

from sim_backend.plant.plant_description import (PlantDescriptionError, load_plant_description, plant_effect_ranges,
                                                 plant_family)
from sim_backend.plant.rod import DEFAULT_ROD_TOML, ROD_EFFECTS, RodDescription, RodDescriptionError, RodPlant


def _toml(tmp_path, text: str):
    path = tmp_path / "plant.toml"
    path.write_text(text)
    return path


def test_configs_rod_plant_toml_is_a_rod_description_off_the_model_values():
    d = RodDescription.from_toml(DEFAULT_ROD_TOML)
    assert plant_family(DEFAULT_ROD_TOML) == "rod"
    assert d.grid_nodes >= 100                              # much finer than the Dahl model's 20 elements
    assert 0.8 < d.bending_stiffness_nmm2 / 900.0 < 0.95     # configs/catheter.toml: EI = 900 N*mm^2
    assert d.mu > 0.2 and d.effects == {}


def test_the_dispatcher_builds_the_family_the_description_names():
    plant, tracker = load_plant_description(DEFAULT_ROD_TOML, {"backlash": {"gear_play_mm": 0.5}})
    assert isinstance(plant, RodPlant)
    assert plant.description.effects == {"backlash": {"gear_play_mm": 0.5}}
    assert (tracker.noise_mm, tracker.dropout, tracker.seed) == (0.05, 0.0, 1)
    dahl, _ = load_plant_description(None)
    assert type(dahl).__name__ == "DahlPlant"


@pytest.mark.parametrize("text, words", [
    ('family = "fem"\n', ["family = 'fem'", "dahl, rod"]),
    ('family = "rod"\n[shaft]\nyoungs_modulus = 3.0\n', ["[shaft] has no key 'youngs_modulus'", "youngs_modulus_mpa"]),
    ('family = "rod"\n[tendon]\n', ["unknown key or table 'tendon'", "tendons"]),
    ('family = "rod"\n[shaft]\ngrid_nodes = 3\n', ["grid_nodes", "[8, 5000]"]),
    ('family = "rod"\n[friction]\nmu = -0.1\n', ["mu must be >= 0"]),
    ('family = "rod"\n[tendons]\nzero_offsets_mm = [0.0, 0.0]\n', ["zero_offsets_mm needs 4 values"]),
    ('family = "rod"\n[effects]\nbacklash = { width_mm = 0.4 }\n',
     ["effect 'backlash' has no parameter 'width_mm'", "gear_play_mm"]),
    ('family = "rod"\n[effects]\nfriction_creep = {}\n', ["unknown rod-plant effect 'friction_creep'", "sheath_creep"]),
    ('family = "rod"\n[effects]\nstiffness_step = { stiffness_ratio = 0.0 }\n', ["stiffness_ratio = 0.0 is outside"]),
    ('family = "rod"\n[tracker]\ndropout = 1.5\n', ["dropout must be in [0, 1)"]),
    ('family = "rod"\n[shaft\n', ["plant.toml"]),
])
def test_a_bad_description_names_the_file_and_the_field(tmp_path, text, words):
    path = _toml(tmp_path, text)
    with pytest.raises((RodDescriptionError, PlantDescriptionError)) as error:
        load_plant_description(path)
    assert str(path) in str(error.value)
    for word in words:
        assert word in str(error.value)


def test_an_effect_given_on_the_command_line_is_checked_like_one_in_the_file():
    with pytest.raises(ValueError, match="effect 'torsion' has no parameter 'twist_rad'; its parameters: helix_rad_per_mm"):
        load_plant_description(DEFAULT_ROD_TOML, {"torsion": {"twist_rad": 0.25}})


def test_every_effect_has_a_drawable_range_around_its_typical_value():
    ranges = plant_effect_ranges("rod")
    assert set(ranges) == set(ROD_EFFECTS)
    for effect_id, entry in ranges.items():
        for name, r in entry["params"].items():
            assert r["draw"] in ("log", "log_signed", "uniform"), (effect_id, name)
            assert r["low"] <= abs(r["typical"]) <= r["high"] or r["draw"] == "uniform", (effect_id, name)
            lo, hi = r["allowed"]
            assert lo <= r["typical"] <= hi and hi >= r["high"], (effect_id, name)
            if r["draw"] != "uniform":
                assert r["low"] > 0.0 and math.isfinite(math.log(r["high"] / r["low"])), (effect_id, name)
                # both signs of a signed draw must be allowed
                assert r["draw"] == "log" or lo <= -r["high"], (effect_id, name)
    with pytest.raises(PlantDescriptionError, match="known plant families: dahl, rod"):
        plant_effect_ranges("fem")


def test_crest_reaches_the_families_and_their_ranges_through_its_backend():
    from crest.backend import plant_description_family, plant_effect_ranges as crest_ranges, plant_from_description

    assert plant_description_family(DEFAULT_ROD_TOML) == "rod" and plant_description_family(None) == "dahl"
    assert crest_ranges("rod") == plant_effect_ranges("rod")
    # the catalog's rate_lag (a creeping drive line) came after the rod plant, which has no drive-line creep yet
    assert set(crest_ranges("dahl")) == {e.id for e in ROD_EFFECTS.values() if e.in_catalog} | {"rate_lag"}
    assert isinstance(plant_from_description(DEFAULT_ROD_TOML, {"gravity": {}}), RodPlant)
