"""The controller's workspace and motion limits, from the testbed configuration and catheter."""
from __future__ import annotations

from control import MotionLimits, Workspace
from crest.config import TestbedConfig
from model import CatheterParams


def workspace_for(config: TestbedConfig, params: CatheterParams) -> Workspace:
    """Ranges narrowed to the axes' soft limits; the pretension from [coordination]."""
    tendon_low = max(axis.soft_min_mm for axis in config.tendon_axes)
    tendon_high = min(axis.soft_max_mm for axis in config.tendon_axes)
    insertion = config.insertion_axis
    return Workspace.from_params(params, pretension_mm=config.coordination.pretension_mm,
                                 tendon_range_mm=(tendon_low, tendon_high),
                                 insertion_range_mm=(insertion.soft_min_mm, insertion.soft_max_mm))


def limits_for(config: TestbedConfig) -> MotionLimits:
    """The slowest tendon axis and the insertion axis, each at 90% of its configured maximum."""
    tendons = config.tendon_axes
    insertion = config.insertion_axis
    return MotionLimits(tendon_velocity_mm_s=0.9 * min(a.max_velocity_mm_s for a in tendons),
                        tendon_acceleration_mm_s2=0.9 * min(a.max_acceleration_mm_s2 for a in tendons),
                        insertion_velocity_mm_s=0.9 * insertion.max_velocity_mm_s,
                        insertion_acceleration_mm_s2=0.9 * insertion.max_acceleration_mm_s2)
