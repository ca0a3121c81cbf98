"""Options shared by the testbed commands, and their translation into a session."""
from __future__ import annotations

import argparse
import math
import os
import sys
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

from control import CONTROLLER_NAMES, Articulation, MotionLimits, Workspace
from crest.backend import fault_kinds
from crest.config import TestbedConfig, load_testbed_config
from crest.config.testbed_config import INSERTION_AXIS_NAME, TENDON_AXIS_NAMES
from crest.experiment.workspace_from_config import limits_for, workspace_for
from crest.session import SessionOptions
from model import CatheterParams
from model.effects import EFFECTS


def add_testbed_options(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("testbed")
    group.add_argument("--config", type=Path, default=None,
                       help="testbed configuration (default configs/testbed.toml: the virtual testbed)")
    group.add_argument("--plant", default=None, metavar="MODULE:CLASS",
                       help="virtual testbed: the plant behind the drives (default: the Dahl catheter)")
    group.add_argument("--plant-config", type=Path, default=None, metavar="PLANT.toml",
                       help="virtual testbed: the plant description (default configs/virtual_plant.toml, the Dahl "
                            "catheter; configs/rod_plant.toml, with family = \"rod\", the independent rod plant)")
    group.add_argument("--fault", action="append", default=[], metavar="AXIS:KIND@SECONDS", help=_fault_help())
    group.add_argument("--effect", action="append", default=[], metavar="ID[:NAME=VALUE,...]", help=_effect_help())
    group.add_argument("--fast", action="store_true",
                       help="virtual testbed: run in simulated time, as fast as this computer allows")


def _fault_help() -> str:
    kinds = fault_kinds()
    axes = ", ".join((*TENDON_AXIS_NAMES, INSERTION_AXIS_NAME))
    return (f"virtual testbed: inject a fault, e.g. tendon3:emcy@2.0 or tracker:disconnect@1.5 (repeatable). "
            f"AXIS is {axes} (kinds {', '.join(kinds['drive'])}) or tracker (kinds {', '.join(kinds['tracker'])}). "
            "SECONDS counts from the start of the command's motion: the trajectory of run, move, demo "
            "and excite (after boot, homing and the move to the start), the jog loop, homing for home")


def _effect_help() -> str:
    effects = "; ".join(f"{effect.id} ({', '.join(effect.param_names)})" for effect in EFFECTS.values())
    return (f"virtual testbed: switch on an unmodelled effect in the plant, e.g. backlash:width_mm=0.4 "
            f"(repeatable; unset parameters take their typical value). IDs (parameters): {effects}")


def add_overwrite_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--overwrite", action="store_true", help="replace output files that already exist")


def add_record_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--record", type=Path, default=None, metavar="PATH",
                        help="record the run: a .csv log path, or a directory for a time-stamped log")
    add_overwrite_option(parser)


def positive_number(text: str) -> float:
    """argparse type: a finite number > 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}")
    return value


def check_output(path: Path | None, overwrite: bool = True, *, directory: bool = False) -> None:
    """Refuse, before anything opens or moves, an output that could only fail at the end.

    A file that exists is refused unless `overwrite`; so is a path whose nearest existing folder is
    a file or cannot be written (missing folders are created when the output is written).
    `directory` paths are folders the command writes into.
    """
    if path is None:
        return
    path = Path(path)
    if path.exists():
        if directory and not path.is_dir():
            raise ValueError(f"{path} is a file; give a folder to write into")
        if not directory and path.is_dir():
            raise ValueError(f"{path} is a folder; give a file path")
        if not directory and not overwrite:
            raise ValueError(f"{path} exists; pass --overwrite to replace it, or choose another path")
    folder = path if directory else path.parent
    folder = folder.absolute()
    while not folder.exists():
        folder = folder.parent
    if not folder.is_dir():
        raise ValueError(f"cannot write {path}: {folder} is a file, not a folder")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise ValueError(f"cannot write {path}: no permission to write in {folder}")


def check_log_outputs(csv_path: Path | None, overwrite: bool) -> None:
    """A log's three files (CSV, JSON sidecar, CAN traffic .blf) checked as in `check_output`."""
    if csv_path is not None:
        for suffix in (".csv", ".json", ".blf"):
            check_output(csv_path.with_suffix(suffix), overwrite)


def planned_record_path(args: argparse.Namespace, stem: str) -> Path | None:
    """`--record` resolved (see `record_path`) and checked before anything opens or moves."""
    path = record_path(args.record, stem)
    check_log_outputs(path, args.overwrite)
    return path


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
                  realtime=not getattr(args, "fast", False), on_notice=print_notice)
    values.update(overrides)
    return SessionOptions(**values)


def print_notice(line: str) -> None:
    print(f"crest: {line}", file=sys.stderr, flush=True)


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


def plant_lines(plants: dict[str, str | None]) -> list[str]:
    """Where logs came from, as their sidecars say ({log: `crest.log.recorded_plant`}): the virtual
    testbed's plant and its family (a result on the Dahl family is in family, on the rod family out of
    family), or that a log names none."""
    named = sorted({plant for plant in plants.values() if plant is not None})
    lines = [f"logs recorded on the virtual testbed, plant: {plant}" for plant in named]
    if None in plants.values():
        lines.append("logs with no plant in their sidecar: hardware, imported, or recorded before crest kept it")
    return lines
