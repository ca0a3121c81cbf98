"""`crest excite --record DIR`: the standard calibration and diagnosis experiment (or, with
--fast-inputs, steps and multisines for the dynamic mode).

Runs the training and the held-out excitation (control/excitation.py: sweeps in several planes,
amplitudes and speeds, reversals and minor loops, insertion changes at constant articulation,
circles, static holds), each after an unrecorded friction-erasing spiral, on the testbed, one
log each, for `crest fit` and `crest gap` (crest/experiment/excitation_run.py).
"""
from __future__ import annotations

import argparse
from pathlib import Path

from crest.cli.common_options import (add_overwrite_option, add_testbed_options, catheter_params, check_log_outputs,
                                      check_output, session_options)
from crest.cli.progress import ProgressBar
from crest.config import load_testbed_config
from crest.experiment.excitation_run import plan_excitation, record_excitation
from crest.session import open_session


def add_parser(sub) -> None:
    parser = sub.add_parser("excite", help="record the training and held-out excitation logs for fit and gap")
    parser.add_argument("--record", type=Path, required=True, metavar="DIR", help="directory for the two logs")
    add_overwrite_option(parser)
    kind = parser.add_mutually_exclusive_group()
    kind.add_argument("--short", action="store_true", help="the short excitation (about 95 s + 65 s)")
    kind.add_argument("--fast-inputs", action="store_true",
                      help="steps at the tendon axes' limits and multisines at up to about 16 mm/s of pull "
                           "(about 53 s + 33 s), for fitting the dynamic mode (crest fit --dynamics)")
    parser.add_argument("--catheter", type=Path, default=None, help="catheter parameters TOML (geometry)")
    add_testbed_options(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    config = load_testbed_config(args.config)
    params = catheter_params(args)
    plan = plan_excitation(config, params, short=args.short, fast_inputs=args.fast_inputs)   # refused before motion
    check_output(args.record, directory=True)
    for name in plan.logs:
        check_log_outputs(args.record / f"{name}.csv", args.overwrite)
    bars: dict[str, ProgressBar] = {}

    def on_cycle(name: str, done: int, total: int) -> None:
        bar = bars.setdefault(name, ProgressBar(total, f"excite {name}"))
        bar.update(done)

    with open_session(session_options(args)) as session:
        results = record_excitation(session, plan, args.record, params, on_cycle, overwrite=args.overwrite)
    for name, result in results.items():
        lost = result.tip_coverage.loss_sentence()
        print(f"wrote {result.log_path} ({result.cycles} cycles, a tip in {result.tip_samples}"
              + (f"; {lost}" if lost else "") + ")")
    train, holdout = results["train"].log_path, results["holdout"].log_path
    print(f"next: crest gap {train} --holdout {holdout} --json gap.json --report gap_report")
    return 0
