"""`crest excite --record DIR`: the standard calibration and diagnosis experiment.

Runs the training and the held-out excitation (control/excitation.py: sweeps in several planes,
amplitudes and speeds, reversals and minor loops, insertion changes at constant articulation,
circles, static holds) on the testbed, one log each, for `crest fit` and `crest gap`.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from control.excitation import ExcitationGeometry, holdout_trajectory, training_trajectory
from crest.cli.common_options import add_testbed_options, catheter_params, session_options
from crest.cli.progress import ProgressBar
from crest.config import load_testbed_config
from crest.driver import AxisTargets
from crest.driver.motion_limits import check_trajectory
from crest.experiment.recorder import ExperimentRecorder
from crest.experiment.time_scaling import slow_to_limits
from crest.session import open_session


def add_parser(sub) -> None:
    parser = sub.add_parser("excite", help="record the training and held-out excitation logs for fit and gap")
    parser.add_argument("--record", type=Path, required=True, metavar="DIR", help="directory for the two logs")
    parser.add_argument("--short", action="store_true", help="the short excitation (about 75 s + 50 s)")
    parser.add_argument("--catheter", type=Path, default=None, help="catheter parameters TOML (geometry)")
    add_testbed_options(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    config = load_testbed_config(args.config)
    params = catheter_params(args)
    geometry = ExcitationGeometry.from_params(params, pretension_mm=config.coordination.pretension_mm)
    rate_hz = 1.0 / config.sync.period_s
    plans = {"train": training_trajectory(geometry, rate_hz, short=args.short),
             "holdout": holdout_trajectory(geometry, rate_hz, short=args.short)}
    samples = {}
    for name, plan in plans.items():
        tendon_mm, insertion_mm, dilation = slow_to_limits(config.sync.period_s, plan.tendon_mm,
                                                           plan.insertion_mm, config)
        if dilation > 1.0:
            print(f"excite {name}: slowed by {dilation:.2f}x to stay inside the axes' velocity and acceleration")
        samples[name] = [AxisTargets(tuple(u), float(length)) for u, length in zip(tendon_mm, insertion_mm)]
    for name, path in samples.items():
        check_trajectory(config, path)                    # refused before anything moves
    written = []
    with open_session(session_options(args)) as session:
        session.testbed.home()
        for name, trajectory in plans.items():
            recorder = ExperimentRecorder(session, args.record / f"{name}.csv", params,
                                          source=f"crest excite: {trajectory.name}", tip_ref=False,
                                          notes="excitation for crest fit / crest gap")
            feed = session.tip_feed()
            progress = ProgressBar(len(samples[name]), f"excite {name}")
            done = [0]

            def on_sample(sample, recorder=recorder, feed=feed, progress=progress, done=done):
                feed.poll(sample.t_s)
                recorder.write(sample, feed.latest_tip_mm)
                done[0] += 1
                progress.update(done[0])

            session.testbed.run_trajectory(samples[name], on_sample=on_sample)
            progress.finish()
            recorder.close()
            written.append(recorder.path)
    for path in written:
        print(f"wrote {path}")
    print(f"next: crest gap {written[0]} --holdout {written[1]} --json gap.json --report gap_report")
    return 0
