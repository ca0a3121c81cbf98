"""Where a candidate's fit starts: its probe values reach down to the small effects the blind benchmark draws.

The blind benchmark draws effect sizes log-uniformly from about 1/20 of the catalog's typical value
(`crest/gap/effect_draws.py`). A fit started at 'off' or at a quarter of the typical value can stall
short of a small effect: dahl seed 91's rate lag of 0.13 of the typical creep compliance fitted to
nothing from there, and to 0.50 of the selection half's error once probed down to 1/16."""
import numpy as np

from crest.gap.effect_draws import DAHL_EFFECT_RANGES
from crest.gap.log_recordings import load_recordings
from model.effects import EFFECTS
from model.gap.calibration import ModelFit, probe_costs
from model.gap.starting_points import probe_values, start_values
from tests.gap.conftest import PLANT_CHANGES, TEST_SETTINGS, prior, record_case

ONE_SIDED = [effect_id for effect_id, candidate in EFFECTS.items() if min(candidate.lower) >= 0.0]


def test_a_one_sided_effect_is_probed_in_octaves_down_to_the_smallest_draws():
    for effect_id in ONE_SIDED:
        candidate, off = EFFECTS[effect_id], start_values(effect_id)
        probes = probe_values(effect_id)
        assert probes[0] == off
        first = candidate.param_names[0]
        sizes = [probe[0] - off[0] for probe in probes[1:]]
        np.testing.assert_allclose(np.divide(sizes[1:], sizes[:-1]), 2.0)      # octaves ...
        assert sizes[-1] == candidate.typical[0] - off[0]                       # ... up to the typical value
        lowest_draw = DAHL_EFFECT_RANGES[effect_id]["params"][first]["low"]
        assert sizes[0] <= 2.0 * lowest_draw, f"{effect_id}: smallest probe {sizes[0]:g}, draws from {lowest_draw:g}"


def test_a_small_creep_starts_its_fit_at_a_probe_next_to_its_size(tmp_path):
    typical_compliance, typical_time = EFFECTS["rate_lag"].typical
    truth = (typical_compliance / 12, typical_time)
    train, _ = record_case(tmp_path, {"rate_lag": truth})
    recordings = TEST_SETTINGS.resolution.prepare_training(load_recordings([train]))
    plant = prior().replace(**PLANT_CHANGES)
    probes = probe_values("rate_lag")
    costs = probe_costs([ModelFit(plant, (0.0,) * 4, {"rate_lag": probe}) for probe in probes], recordings,
                        TEST_SETTINGS.resolution)
    best = probes[int(np.argmin(costs))]
    assert best[0] > 0.0, f"the fit would start with the creep off (costs {costs})"
    assert 0.5 <= best[0] / truth[0] <= 2.0, f"started at {best}, the plant has {truth} (costs {costs})"
