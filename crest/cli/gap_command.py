"""`crest gap`: diagnose the sim-to-real gap of logs, or validate the diagnosis blind.

    crest gap TRAIN.csv [...] --holdout TEST.csv [...] --json OUT.json --report DIR [--effects ID,...]
    crest gap --blind-benchmark --cases 40 --seed S --json OUT.json --report DIR
    crest gap --real-data [DIR] --json OUT.json: every real log held out once (crest.gap.real_data_table)
    crest gap --combine BLIND.json [...] --report DIR: stored blind results scored together, with their
        report and figures (crest.gap.blind_combine)
    either with --scheduler tcp://HOST:PORT: the fits run on a Dask cluster (crest.gap.fit_executor)
"""
from __future__ import annotations

import argparse
import json
import sys
from contextlib import nullcontext
from pathlib import Path

from crest.cli.common_options import check_output, plant_lines
from crest.gap.blind_benchmark import ALL_EFFECTS, run_blind_benchmark
from crest.gap.blind_combine import combined_result
from crest.gap.fit_executor import check_scheduler_address, dask_executor, open_executor
from crest.gap.log_diagnosis import diagnose_logs
from crest.gap.log_recordings import load_recordings
from crest.gap.miss_causes import CAUSE_WORDS, CAUSES
from crest.gap.real_data_table import real_data_table, table_markdown
from crest.log import recorded_plant
from crest.reports.blind_report import write_blind_report
from crest.reports.gap_report import candidate_set_lines, sampling_lines, write_gap_report
from model.effects import EFFECTS
from model.gap.diagnosis import DiagnosisSettings
from model.gap.finite_json import finite_tree


def add_parser(sub) -> None:
    parser = sub.add_parser("gap", help="diagnose the sim-to-real gap: where, which effect, how far it shrinks")
    parser.add_argument("train", nargs="*", type=Path, help="training logs (crest-log/1)")
    parser.add_argument("--holdout", nargs="+", type=Path, default=[], help="held-out logs (other trajectories)")
    parser.add_argument("--json", dest="json_path", type=Path, default=None, help="write the result as JSON")
    parser.add_argument("--report", type=Path, default=None, help="write the report (Markdown) and PNG figures here")
    parser.add_argument("--catheter", default=None, help="starting catheter TOML (default configs/catheter.toml)")
    parser.add_argument("--workers", type=int, default=2, help="parallel candidate fits (default 2)")
    parser.add_argument("--effects", type=effect_ids, default=tuple(EFFECTS), metavar="ID[,ID...]",
                        help="fit only these candidate effects (default: the whole catalog: "
                             f"{', '.join(EFFECTS)}); the verdict is among them")
    parser.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT",
                        help="run the fits on the Dask cluster whose scheduler listens here, instead of on "
                             "--workers local processes; the result is the same")
    parser.add_argument("--blind-benchmark", action="store_true",
                        help="validate instead on virtual-testbed logs whose effect is withheld")
    parser.add_argument("--real-data", nargs="?", const="", default=None, metavar="DIR",
                        help="tabulate calibrated constant curvature, calibrated Dahl and Dahl + verdict as held-out "
                             "RMSE for every real log in DIR (default ../shared/data/continuum_nathan), each held "
                             "out once in a two-fold cross-validation over the files")
    parser.add_argument("--combine", nargs="+", type=Path, default=None, metavar="BLIND.json",
                        help="score stored blind-benchmark results (--blind-benchmark --json) together: every case "
                             "of these files, per family")
    parser.add_argument("--cases", type=int, default=40, help="blind benchmark: number of cases (default 40)")
    parser.add_argument("--seed", type=int, default=0, help="blind benchmark: random seed")
    parser.add_argument("--family", choices=("dahl", "rod", "both"), default="dahl",
                        help="blind benchmark: the plant family (default dahl; both: --cases of each)")
    parser.add_argument("--short", action="store_true", help="blind benchmark: the short excitation (faster)")
    parser.add_argument("--work-dir", type=Path, default=None,
                        help="blind benchmark: keep each case's plant and logs here (default: a temporary folder)")
    parser.set_defaults(handler=run)


def effect_ids(text: str) -> tuple[str, ...]:
    """argparse type: comma-separated ids of the catalog's effects, each once, in the order given."""
    ids = tuple(dict.fromkeys(part.strip() for part in text.split(",") if part.strip()))
    unknown = [effect_id for effect_id in ids if effect_id not in EFFECTS]
    if unknown or not ids:
        cause = f"unknown effect {unknown[0]!r}" if unknown else "no effect given"
        raise argparse.ArgumentTypeError(f"{cause}; the catalog's effects: {', '.join(EFFECTS)}")
    return ids


def _progress(message: str) -> None:
    print(f"crest gap: {message}", file=sys.stderr, flush=True)


def run(args: argparse.Namespace) -> int:
    check_output(args.json_path)                                   # refused now, not after the diagnosis
    check_output(args.report, directory=True)
    check_output(args.work_dir, directory=True)
    if args.scheduler is not None:
        check_scheduler_address(args.scheduler)
    settings = DiagnosisSettings(workers=args.workers, effects=args.effects)
    if args.effects != tuple(EFFECTS) and (args.blind_benchmark or args.combine is not None
                                           or args.real_data is not None):
        raise ValueError("--effects applies to a diagnosis of given logs: --blind-benchmark, --real-data and "
                         "--combine score the whole catalog")
    if args.combine is not None:
        if args.train or args.holdout or args.blind_benchmark or args.real_data is not None:
            raise ValueError("--combine scores stored results; do not pass logs, --blind-benchmark or --real-data")
        combined = combined_result(args.combine)
        _write_json(combined, args.json_path)
        print("\n".join(format_family_score(family, score) for family, score in combined["score"].items()))
        if args.report:
            print(f"report written to {write_blind_report(combined, args.report)}")
        return 0
    if args.real_data is not None:
        if args.train or args.holdout or args.blind_benchmark:
            raise ValueError("--real-data makes its own folds of the real logs; do not pass logs or --blind-benchmark")
        with open_executor(args.scheduler, args.workers) as executor:
            table = real_data_table(Path(args.real_data) if args.real_data else None, settings, _progress, executor,
                                    report_dir=args.report)
        _write_json(table, args.json_path)
        if args.report:
            args.report.mkdir(parents=True, exist_ok=True)
            (args.report / "real_data_table.md").write_text(table_markdown(table) + "\n")
            print(f"report written to {args.report / 'real_data_table.md'} (each fold's gap report in "
                  f"{args.report / 'fold_K'})")
        print(table_markdown(table))
        return 0
    if args.blind_benchmark:
        if args.train or args.holdout:
            raise ValueError("--blind-benchmark makes its own logs; do not pass training or held-out logs")
        # locally each case records and diagnoses in processes of its own; on a cluster its fits go there
        with dask_executor(args.scheduler) if args.scheduler else nullcontext() as executor:
            if args.scheduler:
                _progress(f"fits run on the Dask cluster at {args.scheduler}")
            result = run_blind_benchmark(args.cases, args.seed, family=args.family, short=args.short,
                                         settings=settings, work_dir=args.work_dir, progress=_progress,
                                         executor=executor)
        _write_json(result, args.json_path)
        if args.report:
            print(f"report written to {write_blind_report(result, args.report)}")
        print("\n".join(format_family_score(family, score) for family, score in result["score"].items()))
        return 0
    if not args.train or not args.holdout:
        raise ValueError("give training logs and --holdout logs (recorded on other trajectories), "
                         "e.g. `crest gap train.csv --holdout test.csv`")
    with open_executor(args.scheduler, args.workers) as executor:      # an unreachable scheduler is refused first
        if args.scheduler:
            _progress(f"fits run on the Dask cluster at {args.scheduler}")
        plants = {str(path): recorded_plant(path) for path in [*args.train, *args.holdout]}
        result = diagnose_logs(args.train, args.holdout, args.catheter, settings, progress=_progress,
                               executor=executor)
    result["log_plants"] = plants
    _write_json(result, args.json_path)
    if args.report:
        path = write_gap_report(result, load_recordings(args.holdout), args.report)
        print(f"report written to {path}")
    print(format_verdict(result))
    print("\n".join(plant_lines(plants)))
    return 0


def _write_json(result: dict, path: Path | None) -> None:
    """Strict JSON: every number finite; a non-finite one is written as null and listed with its
    reason under "non_finite" (`finite_tree`)."""
    if path:
        tree, nulls = finite_tree(result)
        if nulls:
            tree["non_finite"] = list(tree.get("non_finite") or []) + nulls
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(tree, indent=2, allow_nan=False))
        print(f"results written to {path}")


def format_verdict(result: dict) -> str:
    verdict = result["verdict"]
    cc = result["constant_curvature"]
    lines = [f"note: {line}" for line in result["coverage"]] + [
             f"baseline: train {result['baseline']['train_rmse_mm']:.3f} mm, held-out "
             f"{result['baseline']['holdout_rmse_mm']:.3f} mm RMS (calibrated constant curvature: train "
             f"{cc['train_rmse_mm']:.3f} mm, held-out {cc['holdout_rmse_mm']:.3f} mm)",
             "gap concentrates in: " + (", ".join(result["concentrated"][:5]) or "no region"),
             f"verdict: {verdict['effect']}" + (f" ({' + '.join(verdict['effects'])})" if len(verdict["effects"]) > 1
                                                else ""),
             *candidate_set_lines(result["settings"]),
             f"held-out (report half) {verdict['holdout_rmse_before_mm']:.3f} -> "
             f"{verdict['holdout_rmse_after_mm']:.3f} mm, shrink {100 * verdict['shrink']:.1f} % "
             f"(selected on the other half: {verdict['shrink_estimate']['method']})"]
    if verdict["confidence_line"]:
        lines.append(verdict["confidence_line"])
    for row in verdict.get("as_good", []):
        lines.append(f"as good on these logs: {row['effect']}: {row['reason']}")
    if verdict["model_form_rms_mm"] is not None and not verdict["effects"]:
        lines.append(f"residual above the noise floor (model form): {verdict['model_form_rms_mm']:.3f} mm RMS")
    for row in verdict["rejected"]:
        lines.append(f"not {row['effect']}: " + "; ".join(row["reasons"]))
    return "\n".join(lines + [f"  {line}" for line in verdict["residual"]] + sampling_lines(result["sampling"]))


def format_score(score: dict) -> str:
    def pct(value: float | None) -> str:
        return "-" if value is None else f"{100 * value:.0f} %"

    shrink = score["shrink_error_pp"] or {}
    counts = score["counts"]
    skipped = [f"{counts[key]} {label}" for key, label in (("skipped", "skipped"), ("no_result", "without a result"))
               if counts.get(key)]
    return "\n".join([
        f"blind benchmark, {score['cases']} cases: {counts['single']} with one effect, {counts['pair']} with two, "
        f"{counts['none']} clean" + (f" ({', '.join(skipped)})" if skipped else ""),
        f"top-1 on single effects: {pct(score['top1_single'])} (target >= 90 %); on the "
        f"{score['counts']['single'] - score['counts']['single_below_noise']} whose effect moves the tip by more "
        f"than the tracker noise: {pct(score['top1_single_above_noise'])}",
        f"'none' on clean cases: {pct(score['none_clean'])} (target >= 80 %)",
        f"pairs: exact {pct(score['pair_exact'])}, at least one found {pct(score['pair_any_found'])}",
        f"shrink error vs oracle: mean {shrink.get('mean', float('nan')):.1f} pp (target <= 10 pp), median "
        f"{shrink.get('median', float('nan')):.1f} pp, within 10 pp in {pct(shrink.get('within_10pp'))} of cases"])


def _pooled_curve(title: str, curve: dict) -> str:
    """One line of the detection-limit curve pooled over every effect: each bin's top-1 of its cases."""
    parts = []
    for row in curve.get(ALL_EFFECTS, []):
        high = "inf" if row["ratio_high"] is None else f"{row['ratio_high']:g}"
        parts.append(f"{row['ratio_low']:g}-{high}: {_count(row['top1'], row['cases'])}")
    return f"{title} {'; '.join(parts) or '-'}"


def format_family_score(family: str, score: dict) -> str:
    """The family's heading, `format_score`, and the scores the issue-14 benchmark adds (counted)."""
    counts = score["counts"]
    lines = [f"== {family} family ==", format_score(score),
             f"top-1 above the detection limit: {_count(score['top1_single_above_detection'], counts['single_above_detection'])}"
             " (target >= 90 %)",
             f"clean cases with no catalog effect named ('none' or 'unexplained'): "
             f"{_count(score['no_catalog_effect_clean'], counts['none'])} (target >= 80 %)"]
    lines.append(_pooled_curve("top-1 by the effect's size / baseline residual, all effects:",
                               score["detection_curve"]))
    if counts.get("single_with_visible_size"):
        lines.append(f"top-1 above the detection limit by the effect's visible part, what the calibrated model "
                     f"cannot absorb: {_count(score['top1_single_above_visible_limit'], counts['single_above_visible_limit'])}")
        lines.append(_pooled_curve("top-1 by the visible part / baseline residual, all effects:",
                                   score["visible_detection_curve"]))
    if counts.get("single_above_detection_with_candidates"):
        lines.append("the true effect ranked first among the candidates above the detection limit, the most any "
                     f"verdict rule could name: {_count(score['truth_ranked_first_above_detection'], counts['single_above_detection_with_candidates'])}")
    misses = score["misses_above_detection"]
    if any(misses[cause] for cause in CAUSES):
        lines.append("misses above the detection limit, by cause: "
                     + "; ".join(f"{misses[cause]} {CAUSE_WORDS[cause]}" for cause in CAUSES if misses[cause]))
        if misses.get("truth_as_good"):
            lines.append(f"misses whose verdict listed the true effect as good on these logs (a tie): "
                         f"{misses['truth_as_good']}")
    for kind, key in (("a clean", "largest_candidate_shrink_clean"),
                      ("an out-of-catalog", "largest_candidate_shrink_out_of_catalog")):
        if score.get(key) is not None:
            lines.append(f"the largest share of the error any candidate removed on {kind} case: {score[key]:.2f}")
    if counts["out_of_catalog"]:
        lines.append(f"out-of-catalog cases 'unexplained': "
                     f"{_count(score['unexplained_out_of_catalog'], counts['out_of_catalog'])} (target >= 80 %); "
                     f"a catalog effect named in {score['catalog_effect_out_of_catalog']}, confidently in "
                     f"{score['confident_catalog_effect_out_of_catalog']} (target: never)")
    confident = score["confident_single_above_detection"]
    lines.append("confident verdicts (the named effect at least halves the report half's error above the noise "
                 f"floor): above the detection limit {confident['right']} right and {confident['wrong']} wrong; "
                 f"on clean cases {score['confident_catalog_effect_clean']}")
    return "\n".join(lines)


def _count(fraction: float | None, cases: int) -> str:
    """'k of n (p %)' for a fraction of n cases; '-' without cases."""
    return "-" if fraction is None else f"{round(fraction * cases)} of {cases} ({100 * fraction:.0f} %)"
