"""`crest fit TRAIN.csv [...] --out catheter.toml [--holdout LOG ...]`: calibrate the base Dahl model on
training logs, and report its tip RMSE on held-out logs it was not fitted to."""
from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import replace
from pathlib import Path

from crest.cli.common_options import check_output, plant_lines, positive_number
from crest.gap.log_diagnosis import calibrate_logs, prior_catheter
from crest.gap.log_recordings import load_recordings
from crest.log import recorded_plant
from model.gap.calibration import rmse_mm, tip_errors
from model.gap.diagnosis import DiagnosisSettings
from model.gap.recording import RecordingError
from model.gap.simulation import Resolution

FITTED = ("bending_stiffness_nmm2", "axial_stiffness_n", "mu", "sigma_n_per_mm2", "fsc_n_per_mm",
          "damping_time_s", "inertia_scale")
DYNAMICS_CHOICES = {"auto": None, "on": True, "off": False}


def add_parser(sub) -> None:
    parser = sub.add_parser("fit", help="calibrate the catheter model on training logs")
    parser.add_argument("train", nargs="+", type=Path, help="training logs (crest-log/1 CSV with JSON sidecar)")
    parser.add_argument("--out", required=True, type=Path, help="where to write the fitted catheter TOML")
    parser.add_argument("--catheter", default=None, help="starting catheter TOML (default configs/catheter.toml)")
    parser.add_argument("--dynamics", choices=list(DYNAMICS_CHOICES), default="auto",
                        help="also fit the damping time and inertia scale: auto (when 30 %% of the logs' "
                             "tendon travel is at >= 8 mm/s: steps, fast multisines), on or off")
    parser.add_argument("--fit-rate-hz", type=positive_number, default=Resolution.fit_rate_hz, metavar="HZ",
                        help="fit and score the logs decimated to about this rate (default %(default)g; a fast log's "
                             "steps need its full rate, e.g. 100 at a 10 ms SYNC); as many seconds of the training "
                             "logs are fitted at any rate")
    parser.add_argument("--holdout", nargs="+", type=Path, default=[], metavar="LOG",
                        help="held-out logs: also report the fitted model's tip RMSE on them (never fitted to)")
    parser.add_argument("--json", dest="json_path", type=Path, default=None,
                        help="also write the fit (values, std, correlations, flags) as JSON")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    check_output(args.out)                                         # refused now, not after the fit
    check_output(args.json_path)
    held = load_recordings(args.holdout)                           # a bad file is refused before the fit
    plants = plant_lines({str(path): recorded_plant(path) for path in args.train})
    settings = DiagnosisSettings(resolution=fit_resolution(args.fit_rate_hz))
    fit = calibrate_logs(args.train, args.catheter, settings,
                         progress=lambda message: print(f"crest fit: {message}", file=sys.stderr, flush=True),
                         fit_dynamics=DYNAMICS_CHOICES[args.dynamics])
    holdout_rmse_mm = rmse_mm(tip_errors(fit, settings.resolution.prepare(held), settings.resolution)) if held else None
    if holdout_rmse_mm is not None and not math.isfinite(holdout_rmse_mm):
        raise RecordingError("the fitted model diverges on the held-out logs; check that they come from the same "
                             "catheter as the training logs")
    prior = prior_catheter(args.catheter)
    fitted = prior.replace(tendon_offset_mm=fit.params.tendon_offset_mm,
                           outer_diameter_mm=fit.params.outer_diameter_mm,
                           **{name: getattr(fit.params, name) for name in FITTED})
    header = [f"# Fitted by `crest fit` on {', '.join(str(p) for p in args.train)}",
              f"# training tip RMSE {fit.train_rmse_mm:.3f} mm (the logs decimated to about {args.fit_rate_hz:g} Hz)",
              "# tendon zero offsets (mm, subtract from the drive position): "
              + ", ".join(f"{z:+.5f}" for z in fit.zero_offsets_mm)]
    if held:
        header.append(f"# held-out tip RMSE {holdout_rmse_mm:.3f} mm on {', '.join(str(p) for p in args.holdout)}")
    header += [f"# FLAG: {flag}" for flag in fit.flags]
    header += [f"# {line}" for line in plants]
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text("\n".join(header) + "\n" + fitted.to_toml())
    if args.json_path:
        args.json_path.parent.mkdir(parents=True, exist_ok=True)
        sampling = settings.resolution.sampling(load_recordings(args.train), held)
        args.json_path.write_text(json.dumps({**fit.as_dict(), "holdout_rmse_mm": holdout_rmse_mm,
                                              "holdout": [str(p) for p in args.holdout], "sampling": sampling},
                                             indent=2))
    print(f"{'parameter':<24} {'value':>12} {'std':>10}")
    for name, value, std in zip(fit.names, fit.values, fit.std):
        print(f"{name:<24} {value:>12.5g} {std:>10.2g}")
    print(f"training tip RMSE {fit.train_rmse_mm:.3f} mm")
    if held:
        print(f"held-out tip RMSE {holdout_rmse_mm:.3f} mm ({', '.join(r.name for r in held)})")
    for a, b, c in fit.strongest_correlations():
        print(f"correlated: {a} / {b} ({c:+.2f})")
    for flag in fit.flags:
        print(f"FLAG: {flag} (the model may be bending this parameter to hide a missing effect; try `crest gap`)")
    print("\n".join(plants))
    print(f"wrote {args.out}")
    return 0


def fit_resolution(rate_hz: float) -> Resolution:
    """The diagnosis' resolution at `rate_hz`, with its cap on training samples scaled by the rate,
    so that a fit at any rate sees the same seconds of log:

        max_fit_samples(rate) = max_fit_samples(default) * rate / fit_rate_hz(default)
    """
    default = Resolution()
    return replace(default, fit_rate_hz=rate_hz,
                   max_fit_samples=max(1, round(default.max_fit_samples * rate_hz / default.fit_rate_hz)))
