"""Options shared by the testbed commands, and their translation into a session."""
from __future__ import annotations

import argparse
from datetime import datetime
from pathlib import Path

from dataclasses import dataclass

from control import CONTROLLER_NAMES, Articulation, MotionLimits, Workspace
from crest.config import TestbedConfig, load_testbed_config
from crest.experiment.workspace_from_config import limits_for, workspace_for
from crest.session import SessionOptions
from model import CatheterParams


def add_testbed_options(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("testbed")
    group.add_argument("--config", type=Path, default=None,
                       help="testbed configuration (default configs/testbed.toml: the virtual testbed)")
    group.add_argument("--plant", default=None, metavar="MODULE:CLASS",
                       help="virtual testbed: the plant behind the drives (default: the Dahl catheter)")
    group.add_argument("--plant-config", type=Path, default=None, metavar="PLANT.toml",
                       help="virtual testbed: the Dahl catheter's description (default configs/virtual_plant.toml)")
    group.add_argument("--fault", action="append", default=[], metavar="AXIS:KIND@SECONDS",
                       help="virtual testbed: inject a fault, e.g. tendon3:emcy@2.0 or tracker:disconnect@1.5")
    group.add_argument("--effect", action="append", default=[], metavar="ID[:NAME=VALUE,...]",
                       help="virtual testbed: switch on an unmodelled effect in the plant, e.g. backlash:width_mm=0.4")
    group.add_argument("--fast", action="store_true",
                       help="virtual testbed: run in simulated time, as fast as this computer allows")


def add_record_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--record", type=Path, default=None, metavar="PATH",
                        help="record the run: a .csv log path, or a directory for a time-stamped log")


def add_controller_options(parser: argparse.ArgumentParser, default: str = "cc") -> None:
    parser.add_argument("--controller", choices=CONTROLLER_NAMES, default=default,
                        help=f"cc (constant curvature), dahl (friction-aware feedforward), dahl+fb "
                             f"(feedforward + tracker feedback); default {default}")
    parser.add_argument("--catheter", type=Path, default=None, metavar="PARAMS.toml",
                        help="the controller's catheter model parameters (default configs/catheter.toml)")


def parse_effect(text: str) -> tuple[str, dict]:
    """'backlash:width_mm=0.4' -> ('backlash', {'width_mm': 0.4}); 'gravity' -> ('gravity', {})."""
    effect_id, _, settings = text.partition(":")
    values = {}
    for item in filter(None, settings.split(",")):
        name, sep, value = item.partition("=")
        try:
            values[name.strip()] = float(value)
        except ValueError:
            sep = ""
        if not sep:
            raise ValueError(f"--effect {text!r}: expected ID[:NAME=VALUE,...] with numeric values")
    return effect_id.strip(), values


def session_options(args: argparse.Namespace, **overrides) -> SessionOptions:
    effects = dict(parse_effect(text) for text in getattr(args, "effect", []))
    values = dict(config_path=args.config, plant=args.plant, plant_config=args.plant_config,
                  faults=tuple(args.fault), effects=effects,
                  realtime=not getattr(args, "fast", False))
    values.update(overrides)
    return SessionOptions(**values)


def catheter_params(args: argparse.Namespace) -> CatheterParams:
    path = getattr(args, "catheter", None)
    return CatheterParams.from_toml(path) if path else CatheterParams.from_toml()


def record_path(record: Path | None, stem: str) -> Path | None:
    """A .csv path as given, or a time-stamped `<stem>-YYYYmmdd-HHMMSS.csv` in the given directory."""
    if record is None:
        return None
    if record.suffix.lower() == ".csv":
        return record
    return record / f"{stem}-{datetime.now().strftime('%Y%m%d-%H%M%S')}.csv"


@dataclass(frozen=True)
class MotionPlan:
    """What a motion command plans with, before anything is opened or moves."""

    config: TestbedConfig
    params: CatheterParams
    workspace: Workspace
    limits: MotionLimits
    period_s: float
    start: Articulation        # where the catheter rests after homing


def motion_plan(args: argparse.Namespace) -> MotionPlan:
    config = load_testbed_config(args.config)
    params = catheter_params(args)
    return MotionPlan(config, params, workspace_for(config, params), limits_for(config), config.sync.period_s,
                      Articulation(0.0, 0.0, config.insertion_axis.home_position_mm))
