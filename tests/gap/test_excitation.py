"""The standard excitation (issue 6, `crest excite`): every primitive, inside the testbed's limits as it
is (no slowing down), different trajectories for training and held-out."""
import numpy as np
import pytest

from control.excitation import holdout_trajectory, training_trajectory
from crest.config import load_testbed_config
from crest.experiment.excitation_run import plan_excitation
from crest.experiment.workspace_from_config import limits_for, workspace_for
from model import CatheterParams, DahlCatheter
from model.gap.calibration import FAST_TENDON_SPEED_MM_S, FAST_TRAVEL_SHARE

CONFIG = load_testbed_config()


@pytest.fixture(scope="module")
def plans():
    return {short: plan_excitation(CONFIG, CatheterParams.from_toml(), short=short) for short in (False, True)}


def assert_within_axis_limits(trajectory):
    """The constant-curvature commands move no axis faster or harder than it may, from rest."""
    dt = CONFIG.sync.period_s
    assert trajectory.period_s == dt
    for axes, kind in ((trajectory.tendon_mm, CONFIG.tendon_axes[0]), (trajectory.insertion_mm[:, None],
                                                                        CONFIG.insertion_axis)):
        path = np.vstack([axes[:1], axes[:1], axes])          # from rest at the start
        assert np.abs(np.diff(path, axis=0)).max() / dt <= kind.max_velocity_mm_s
        assert np.abs(np.diff(path, n=2, axis=0)).max() / dt ** 2 <= kind.max_acceleration_mm_s2
        assert kind.soft_min_mm <= axes.min() and axes.max() <= kind.soft_max_mm


@pytest.mark.parametrize("name", ["train", "holdout"])
@pytest.mark.parametrize("short", [False, True])
def test_trajectory_holds_every_primitive_within_the_axis_limits(plans, name, short):
    trajectory = plans[short].logs[name]
    labels = " | ".join(sorted(set(trajectory.labels)))
    for primitive in ("static hold", "sweep", "minor loops", "insertion change", "circle"):
        assert primitive in labels
    assert_within_axis_limits(trajectory)
    # antagonistic pairs from the constant-curvature inverse: u1 + u3 = u2 + u4 = 2 * pretension
    pair_sums = trajectory.tendon_mm[:, :2] + trajectory.tendon_mm[:, 2:]
    assert np.allclose(pair_sums, 2 * CONFIG.coordination.pretension_mm)


def test_trajectory_starts_and_ends_straight_at_the_home_free_length(plans):
    plan = plans[True]
    for trajectory in (plan.conditioning, *plan.logs.values()):
        assert np.allclose(trajectory.start.bend_rad, 0.0) and np.allclose(trajectory.bend_rad[-1], 0.0)
        assert trajectory.insertion_mm[-1] == pytest.approx(trajectory.start.insertion_mm)


@pytest.mark.parametrize("mu", [0.15, 0.3])
def test_conditioning_erases_the_friction_memory(plans, mu):
    """After the training excitation and the conditioning spiral, the catheter follows the held-out
    excitation as a fresh one does (the state the model starts from), from its very first sample, the
    start of its first static hold: a spiral decaying linearly over the same turns left the tip 0.3-0.4 mm
    off there. Without the spiral it does not follow."""
    plan = plans[True]
    assert_within_axis_limits(plan.conditioning)
    params = CatheterParams.from_toml().replace(mu=mu)
    held = plan.logs["holdout"]
    fresh = DahlCatheter(params, 10).run(held.tendon_mm, held.insertion_mm, held.period_s)
    gaps, starts = {}, {}
    for conditioned in (False, True):
        model = DahlCatheter(params, 10)
        runs = [plan.logs["train"]] + ([plan.conditioning] if conditioned else [])
        for run in runs:
            model.run(run.tendon_mm, run.insertion_mm, run.period_s)
        tips = model.run(held.tendon_mm, held.insertion_mm, held.period_s)
        gaps[conditioned] = float(np.sqrt(np.mean(np.sum((tips - fresh) ** 2, axis=1))))
        starts[conditioned] = float(np.linalg.norm(tips[0] - fresh[0]))
    assert gaps[True] < 0.01 and starts[True] < 0.02
    assert gaps[False] > 0.3 and starts[False] > 0.3


def test_held_out_trajectory_differs_from_training(plans):
    def primitives(trajectory):
        return {label for label in trajectory.labels if "sweep" in label or "circle" in label}

    train, held = primitives(plans[False].logs["train"]), primitives(plans[False].logs["holdout"])
    assert train and held and not train & held


def test_repeated_trajectory_plays_it_back_to_back(plans):
    one = plans[True].logs["train"]
    trajectory = one.repeated(3)
    assert len(trajectory) == 3 * len(one)
    assert np.array_equal(trajectory.tendon_mm[len(one):2 * len(one)], one.tendon_mm)
    assert np.all(np.diff(trajectory.t_s) > 0)


def test_other_sample_rates_keep_the_shape():
    workspace, limits = workspace_for(CONFIG, CatheterParams.from_toml()), limits_for(CONFIG)
    fine = training_trajectory(workspace, limits, 0.01, short=True)
    coarse = training_trajectory(workspace, limits, 0.05, short=True)
    assert coarse.duration_s == pytest.approx(fine.duration_s, rel=0.02)
    assert holdout_trajectory(workspace, limits, 0.05, short=True).duration_s < coarse.duration_s


@pytest.mark.parametrize("name", ["train", "holdout"])
def test_fast_input_excitation_steps_at_the_axis_limits_and_is_fast(name):
    """`crest excite --fast-inputs`: steps and multisines inside the axes' limits, fast enough that
    `crest fit --dynamics auto` fits the dynamic mode (30 % of the tendon travel at >= 8 mm/s)."""
    trajectory = plan_excitation(CONFIG, CatheterParams.from_toml(), fast_inputs=True).logs[name]
    labels = " | ".join(sorted(set(trajectory.labels)))
    assert "step to" in labels and "multisine" in labels
    assert_within_axis_limits(trajectory)
    travel_mm = np.abs(np.diff(trajectory.tendon_mm, axis=0)).max(axis=1)
    speed_mm_s = travel_mm / trajectory.period_s
    assert speed_mm_s.max() > 0.85 * trajectory.limits.tendon_velocity_mm_s      # the steps
    assert travel_mm[speed_mm_s >= FAST_TENDON_SPEED_MM_S].sum() >= FAST_TRAVEL_SHARE * travel_mm.sum()
    assert np.allclose(trajectory.bend_rad[-1], 0.0)
