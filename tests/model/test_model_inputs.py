"""Bad input is refused with a clear error and leaves the model state unchanged."""
import dataclasses

import numpy as np
import pytest

from model import CatheterParams, DahlCatheter, ModelInputError, ParamsError, SolverBudgetExceeded
from tests.model.conftest import articulation


def assert_same_state(a, b):
    for field in dataclasses.fields(a):
        assert np.array_equal(getattr(a, field.name), getattr(b, field.name)), field.name


@pytest.mark.parametrize("tendons,insertion,match", [
    ([np.nan, 0, 0, 0], 80.0, "tendon 1"),
    ([0, np.inf, 0, 0], 80.0, "tendon 2"),
    ([0, 0, 0, 99.0], 80.0, "tendon 4 .*outside"),
    ([1, 0, -1, 0], -5.0, "free length"),
    ([1, 0, -1, 0], np.nan, "insertion"),
])
def test_bad_command_raises_and_keeps_state(params, tendons, insertion, match):
    model = DahlCatheter(params)
    model.move_to(articulation(params, 60.0))
    before = model.snapshot()
    with pytest.raises(ModelInputError, match=match):
        model.move_to(tendons, insertion)
    assert_same_state(before, model.state)


def test_a_run_over_its_iteration_budget_stops_at_once_and_keeps_state(params):
    model = DahlCatheter(params)
    model.move_to(articulation(params, 30.0))
    before = model.snapshot()
    ramp_mm = np.linspace(0.0, 4.0, 200)
    path = np.column_stack([ramp_mm, np.zeros(200), -ramp_mm, np.zeros(200)])
    needed = DahlCatheter(params)
    needed.move_to(articulation(params, 30.0))
    start_iterations = needed.solver_iterations[0]
    needed.run(path)
    assert needed.solver_iterations[0] - start_iterations > 100
    with pytest.raises(SolverBudgetExceeded, match=r"stopped at sample \d of 200"):
        model.run(path, max_solver_iterations=5)
    assert_same_state(before, model.state)


def test_bad_path_in_run_rejected_before_any_step(params):
    model = DahlCatheter(params)
    before = model.snapshot()
    path = np.zeros((10, 4))
    path[7, 2] = np.nan
    with pytest.raises(ModelInputError, match="sample 7"):
        model.run(path)
    assert_same_state(before, model.state)


def test_defaults_come_from_configs_catheter_toml():
    assert CatheterParams.from_toml() == CatheterParams()


@pytest.mark.parametrize("field,value", [("free_length_mm", -10.0), ("mu", float("nan")),
                                         ("bending_stiffness_nmm2", 0.0), ("tendon_offset_mm", 3.5)])
def test_bad_parameter_names_the_field(field, value):
    with pytest.raises(ParamsError, match=field):
        CatheterParams().replace(**{field: value})


def test_bad_toml_names_file_and_field(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("[friction]\nmu = -0.5\n")
    with pytest.raises(ParamsError, match=r"bad\.toml.*mu"):
        CatheterParams.from_toml(path)
    path.write_text("[friction]\nmuu = 0.5\n")
    with pytest.raises(ParamsError, match="muu"):
        CatheterParams.from_toml(path)


def test_params_round_trip_through_toml(tmp_path):
    params = CatheterParams().replace(mu=0.33, sigma_n_per_mm2=2.5)
    path = tmp_path / "p.toml"
    path.write_text(params.to_toml())
    assert CatheterParams.from_toml(path) == params
