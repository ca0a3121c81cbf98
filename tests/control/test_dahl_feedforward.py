"""The Dahl feedforward inverts the model it carries, and carries it with what was sent."""
import math

import numpy as np

from model import DahlCatheter

from control import Articulation, DahlFeedforward, tendons_from_articulation
from control.trajectories import articulation_sweep


def test_with_a_perfect_model_the_tip_follows_the_target_through_a_reversal(params, workspace, limits):
    """At 0.5 rad/s no limit binds. (Faster, the free-length change that undoes the shape
    hysteresis right after the reversal runs into the 10 mm/s insertion limit and the tip lags.)"""
    trajectory = articulation_sweep(workspace, limits, angle_rad=math.radians(150), plane_rad=0.4,
                                    velocity_rad_s=0.5, acceleration_rad_s2=4.0, hold_s=0.2)
    controller = DahlFeedforward(workspace, limits, n_elements=10)
    plant = DahlCatheter(params, 10)
    errors, predicted = [], []
    for setpoint in trajectory:
        command = controller.command(setpoint)
        tip = plant.move_to(command.tendon_mm, command.insertion_mm)
        errors.append(np.linalg.norm(tip - setpoint.tip_mm))
        predicted.append(np.linalg.norm(tip - command.predicted_tip_mm))
    # the model state is the plant's state: both were driven with exactly the commands sent
    assert max(predicted) < 1e-9
    errors = np.array(errors)
    print(f"perfect model: RMS {np.sqrt(np.mean(errors ** 2)):.3f} mm, max {errors.max():.3f} mm")
    assert np.sqrt(np.mean(errors ** 2)) < 0.05


def test_after_a_round_trip_the_feedforward_returns_straight_despite_friction(params, workspace, limits):
    """Constant-curvature commands back to 0 leave the catheter bent by its friction state; the inverse does not."""
    trajectory = articulation_sweep(workspace, limits, angle_rad=math.radians(180), velocity_rad_s=1.5,
                                    acceleration_rad_s2=4.0, hold_s=0.5)
    controller = DahlFeedforward(workspace, limits, n_elements=10)
    plant = DahlCatheter(params, 10)
    for setpoint in trajectory:
        command = controller.command(setpoint)
        tip = plant.move_to(command.tendon_mm, command.insertion_mm)
    cc_plant = DahlCatheter(params, 10)
    for setpoint in trajectory:
        cc_tip = cc_plant.move_to(tendons_from_articulation(setpoint.articulation, workspace.tendon_offset_mm,
                                                            workspace.pretension_mm), setpoint.insertion_mm)
    print(f"residual bend after 0-180-0: cc {np.hypot(*cc_tip[:2]):.2f} mm, dahl {np.hypot(*tip[:2]):.3f} mm")
    assert np.hypot(*cc_tip[:2]) > 0.5
    assert np.hypot(*tip[:2]) < 0.1


def test_free_length_stays_within_the_allowed_offset_of_the_setpoint(params, workspace, limits):
    """Reaching the arc's tip at 180 deg takes the free length ~5 mm off; bounded to 2 mm it stays there."""
    trajectory = articulation_sweep(workspace, limits, angle_rad=math.radians(180), velocity_rad_s=2.0,
                                    acceleration_rad_s2=4.0, back=False)
    free = DahlFeedforward(workspace, limits, n_elements=10)
    bounded = DahlFeedforward(workspace, limits, n_elements=10, max_insertion_offset_mm=2.0)
    offsets_free, offsets_bounded = [], []
    for setpoint in trajectory:
        offsets_free.append(abs(free.command(setpoint).insertion_mm - setpoint.insertion_mm))
        offsets_bounded.append(abs(bounded.command(setpoint).insertion_mm - setpoint.insertion_mm))
    assert max(offsets_free) > 3.0
    assert max(offsets_bounded) <= 2.0 + 1e-9


def test_reset_at_the_homed_free_length_starts_the_model_there(params, workspace, limits):
    """After homing the insertion axis sits at 20 mm (configs/testbed.toml): the model must start there too."""
    controller = DahlFeedforward(workspace, limits, n_elements=10)
    controller.reset(insertion_mm=20.0)
    assert controller.model.free_length_mm == 20.0
    trajectory = articulation_sweep(workspace, limits, angle_rad=math.radians(60), velocity_rad_s=1.0,
                                    acceleration_rad_s2=4.0, start=Articulation(0.0, 0.0, 20.0))
    plant = DahlCatheter(params, 10)
    plant.move_to(np.zeros(4), 20.0)
    for setpoint in trajectory:
        command = controller.command(setpoint)
        tip = plant.move_to(command.tendon_mm, command.insertion_mm)
        assert np.linalg.norm(tip - setpoint.tip_mm) < 0.1
