"""The effect examples commented in the shipped plant descriptions are ones the plant accepts: a user
uncomments one line and gets that effect, not an error about a parameter that was renamed."""
import re
import tomllib
from pathlib import Path

import pytest

from sim_backend.plant.plant_description import load_plant_description

CONFIGS = Path(__file__).resolve().parents[2] / "configs"
EXAMPLE = re.compile(r"^# (\w+) = (\{[^}]*\})")


def examples(path: Path) -> list[tuple[str, dict]]:
    found = [EXAMPLE.match(line) for line in path.read_text().splitlines()]
    return [(m.group(1), tomllib.loads(f"x = {m.group(2)}")["x"]) for m in found if m]


@pytest.mark.parametrize("name, count", [("virtual_plant.toml", 10), ("rod_plant.toml", 14)])
def test_every_commented_effect_example_loads(name, count):
    path = CONFIGS / name
    found = examples(path)
    assert len(found) == count
    for effect_id, values in found:
        load_plant_description(path, effects={effect_id: values})
