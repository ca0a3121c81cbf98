"""The gap report: Markdown and PNG figures of a diagnosis (`crest gap --report DIR`).

Figures (Agg renderer, no pyplot state):
- residual_by_region.png: held-out tip RMSE per region, baseline and with the chosen effect(s);
- tip_traces.png: measured tip against the baseline model and the model with the effect(s);
- candidates.png: held-out RMSE of every candidate against the baseline and the noise floor.
The model tips are recomputed from the fits stored in the result, at the diagnosis' resolution.
"""
from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from crest.paper.figure_output import new_figure, save_png
from model.effects import EFFECTS
from model.gap.calibration import ModelFit
from model.gap.recording import Recording
from model.gap.simulation import Resolution, predict_tips

GROUPS = ("articulation", "plane", "insertion", "motion", "speed", "tension", "time")


def write_gap_report(result: dict, holdout: Sequence[Recording], out_dir: Path | str) -> Path:
    """Write report.md and the figures into out_dir (created); returns the Markdown path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    resolution = Resolution(**result["settings"]["resolution"])
    held = resolution.prepare(holdout)
    baseline = ModelFit.from_dict(result["baseline"]["fit"])
    final = ModelFit.from_dict(result["verdict"]["fit"])
    save_png(_region_figure(result), out / "residual_by_region.png")
    save_png(_trace_figure(held, baseline, final, result["verdict"], resolution), out / "tip_traces.png")
    save_png(_candidate_figure(result), out / "candidates.png")
    path = out / "report.md"
    path.write_text(markdown(result))
    return path


def _region_figure(result: dict) -> Figure:
    where = result["where"]
    after = {row["region"]: row["after_mm"] for row in result["verdict"]["shrink_by_region"]}
    groups = [g for g in GROUPS if any(row["group"] == g for row in where)]
    figure = new_figure(11.0, 2.3 * len(groups))
    axes = figure.subplots(len(groups), 1, squeeze=False)[:, 0]
    for ax, group in zip(axes, groups):
        rows = [row for row in where if row["group"] == group]
        rows.sort(key=lambda row: row["order"])
        x = np.arange(len(rows))
        ax.bar(x - 0.2, [row["rmse_mm"] for row in rows], 0.4, label="baseline", color="tab:red")
        if after:
            ax.bar(x + 0.2, [after.get(row["region"], np.nan) for row in rows], 0.4,
                   label="with " + "+".join(result["verdict"]["effects"]), color="tab:blue")
        floor = result["baseline"]["noise_floor_mm"]
        if floor is not None:
            ax.axhline(floor, color="0.4", linestyle=":", label="noise floor")
        ax.set_xticks(x, [row["region"] for row in rows], rotation=12, fontsize=7)
        ax.set_ylabel("tip RMSE [mm]")
        ax.set_title(f"held-out residual by {group}", fontsize=9)
    axes[0].legend(fontsize=7)
    return figure


def _trace_figure(held: Sequence[Recording], baseline: ModelFit, final: ModelFit, verdict: dict,
                  resolution: Resolution) -> Figure:
    recording = held[0]
    before = predict_tips(baseline.params, baseline.terms(), np.asarray(baseline.zero_offsets_mm), recording,
                          resolution)
    after = predict_tips(final.params, final.terms(), np.asarray(final.zero_offsets_mm), recording, resolution)
    figure = new_figure(11.0, 7.0)
    axes = figure.subplots(3, 1, sharex=True)
    label = "+".join(verdict["effects"]) or "none (= baseline)"
    for k, (ax, axis) in enumerate(zip(axes, "xyz")):
        ax.plot(recording.t_s, recording.tip_mm[:, k], ".", color="0.3", markersize=2, label="measured")
        ax.plot(recording.t_s, before[:, k], color="tab:red", linewidth=1.0, label="baseline model")
        ax.plot(recording.t_s, after[:, k], color="tab:blue", linewidth=1.0, linestyle="--", label=f"with {label}")
        ax.set_ylabel(f"tip {axis} [mm]")
    axes[0].set_title(f"held-out tip traces: {recording.name}", fontsize=9)
    axes[0].legend(fontsize=7, ncol=3)
    axes[-1].set_xlabel("t [s]")
    return figure


def _candidate_figure(result: dict) -> Figure:
    rows = [c for c in result["candidates"] if c["holdout_rmse_mm"] is not None]
    figure = new_figure(8.0, 3.5)
    ax = figure.subplots()
    ax.barh([c["effect"] for c in rows][::-1], [c["holdout_rmse_mm"] for c in rows][::-1], color="tab:blue")
    ax.axvline(result["baseline"]["holdout_rmse_mm"], color="tab:red", label="baseline")
    if result["baseline"]["noise_floor_mm"] is not None:
        ax.axvline(result["baseline"]["noise_floor_mm"], color="0.4", linestyle=":", label="noise floor")
    ax.set_xlabel("held-out tip RMSE [mm]")
    ax.set_title("candidate effects (best score at the top)", fontsize=9)
    ax.legend(fontsize=7)
    return figure


def markdown(result: dict) -> str:
    """The report text: verdict, where, candidates, signatures, parameter movement, calibration flags."""
    base, verdict = result["baseline"], result["verdict"]
    floor = base["noise_floor_mm"]
    lines = ["# Sim-to-real gap report", "",
             f"Training: {', '.join(result['settings']['train'])}  ",
             f"Held out: {', '.join(result['settings']['holdout'])}", "",
             "Sampling:", ""] + [f"- {line}" for line in sampling_lines(result["sampling"])] + [
             f"- **{line}**" for line in result["coverage"]] + ["",
             "## Verdict", "",
             f"- effect: **{verdict['effect']}**" + (f" (selected: {', '.join(verdict['effects'])})"
                                                    if len(verdict["effects"]) > 1 else ""),
             *[f"- {line}" for line in candidate_set_lines(result["settings"])],
             f"- held-out tip RMSE {verdict['holdout_rmse_before_mm']:.3f} mm -> "
             f"{verdict['holdout_rmse_after_mm']:.3f} mm, shrink {100 * verdict['shrink']:.1f} % on the report half "
             f"({verdict['shrink_estimate']['method']}; on the selection half {100 * verdict['selection_shrink']:.1f} %)",
             *([f"- {verdict['confidence_line']}"] if verdict['confidence_line'] else []),
             f"- training RMSE of the baseline {base['train_rmse_mm']:.3f} mm; tracker noise floor "
             + (f"{floor:.3f} mm" if floor is not None else "unknown (no static holds in the logs)")]
    for effect_id, params in verdict["params"].items():
        lines.append(f"- {effect_id}: " + ", ".join(f"{k} = {v:.4g}" for k, v in params.items()))
    lines += [f"- named before {row['effect']}, which scored higher: {row['reason']}"
              for row in verdict.get("simpler_than", [])]
    lines += [f"- as good on these logs: {row['effect']}: {row['reason']}" for row in verdict.get("as_good", [])]
    lines += ["", "Held-out tip RMSE per recording (all evaluated rows), against calibrated constant curvature:", "",
              "| recording | calibrated CC | calibrated Dahl | Dahl + verdict |", "|---|---|---|---|"]
    lines += [f"| {row['recording']} | {row['constant_curvature_mm']:.3f} mm | {row['baseline_mm']:.3f} mm | "
              f"{row['verdict_mm']:.3f} mm |" for row in result["holdout_by_recording"]]
    lines.append("")
    if verdict["model_form_rms_mm"] is not None:
        lines.append(f"- residual above the noise floor after the verdict (model form, what no effect in the "
                     f"catalog removed): {verdict['model_form_rms_mm']:.3f} mm RMS, concentrated in "
                     + (", ".join(verdict["residual_concentrated"]) or "no region (spread evenly)"))
    if verdict["rejected"]:
        lines += ["", "Why no candidate is the verdict (best three):", ""]
        lines += [f"- {row['effect']}: " + ("; ".join(row["reasons"]) or "-") for row in verdict["rejected"]]
    lines += ["", "Residual after the verdict:", ""] + [f"- {line}" for line in verdict["residual"]]
    lines += ["", "## Where the gap lies (held-out, baseline model)", "",
              "Concentrated in: " + (", ".join(result["concentrated"]) or "no region (spread evenly)"), "",
              "![residual by region](residual_by_region.png)", "",
              "| group | region | RMSE mm | share | samples | concentration | shrink |", "|---|---|---|---|---|---|---|"]
    shrink = {row["region"]: row["shrink"] for row in verdict["shrink_by_region"]}
    for row in sorted(result["where"], key=lambda r: r["order"]):
        s = shrink.get(row["region"])
        lines.append(f"| {row['group']} | {row['region']} | {row['rmse_mm']:.3f} | {row['share']:.2f} | "
                     f"{row['samples']} | {row['concentration']:.2f} | {'-' if s is None else f'{100 * s:.0f} %'} |")
    lines += ["", "![tip traces](tip_traces.png)", "", "## Candidates (held-out)", "",
              "![candidates](candidates.png)", "",
              "| effect | parameters | held-out RMSE mm | shrink | signature match | score | rejected because |",
              "|---|---|---|---|---|---|---|"]
    for c in result["candidates"] + result["pairs"]:
        params = c["params"] if len(c["effects"]) == 1 else {f"{e}.{k}": v for e, p in c["params"].items()
                                                            for k, v in p.items()}
        text = ", ".join(f"{k} = {v:.3g}" for k, v in params.items())
        rmse = "diverged" if c["holdout_rmse_mm"] is None else f"{c['holdout_rmse_mm']:.3f}"
        shrink_text = "-" if c["shrink"] is None else f"{100 * c['shrink']:.1f} %"
        score = "-" if c["score"] is None else f"{c['score']:.3f}"
        match = "-" if c["signature_match"] is None else f"{c['signature_match']:.2f}"
        why = "; ".join(c.get("rejected") or []) or "-"
        lines.append(f"| {c['effect']} | {text} | {rmse} | {shrink_text} | {match} | {score} | {why} |")
    lines += ["", "## Signatures of the baseline residual", ""] + _signature_lines(result["signatures"])
    if verdict["base_parameter_change"]:
        lines += ["", "## Base parameters when the effect is added", "",
                  "| parameter | baseline | with effect | change |", "|---|---|---|---|"]
        for row in verdict["base_parameter_change"]:
            change = f"{100 * row['relative_change']:+.1f} %" if row["relative_change"] is not None \
                else f"{row['change']:+.4f}"
            lines.append(f"| {row['name']} | {row['baseline']:.4g} | {row['with_effect']:.4g} | {change} |")
    fit = base["fit"]
    lines += ["", "## Baseline calibration", "", "| parameter | value | std (lower bound) |", "|---|---|---|"]
    lines += [f"| {name} | {p['value']:.4g} | {'unidentified' if p['std'] is None else format(p['std'], '.2g')} |"
              for name, p in fit["parameters"].items()]
    lines += ["", "Flags: " + ("; ".join(fit["flags"]) or "none"), "",
              "Strong correlations: " + ("; ".join(f"{c['a']} / {c['b']}: {c['correlation']:+.2f}"
                                                   for c in fit["strong_correlations"]) or "none"), ""]
    return "\n".join(lines)


def candidate_set_lines(settings: dict) -> list[str]:
    """One line when the diagnosis fitted only some of the catalog's effects (`crest gap --effects`): the
    verdict is then among those alone. No line for the whole catalog."""
    fitted = settings["effects"]
    if set(fitted) == set(EFFECTS):
        return []
    return [f"candidates: only {', '.join(fitted)} ({len(fitted)} of the catalog's {len(EFFECTS)} effects, "
            "--effects): the verdict is among them"]


def sampling_lines(sampling: dict) -> list[str]:
    """What of the logs the fits and the held-out error used (the diagnosis' "sampling" block), one line each."""
    def part(rows: list[dict], capped: bool) -> str:
        return "; ".join(f"{row['recording']}: {row['rows_used']} of {row['rows']} rows"
                         + (f" (one in {row['decimation']})" if row["decimation"] > 1 else "")
                         + (f", the first {row['duration_used_s']:.0f} s of {row['duration_s']:.0f} s" if capped else "")
                         for row in rows)

    fit = (f"fits use {sampling['train_rows_used']} of {sampling['train_rows']} training rows"
           + (f", decimated to about {sampling['fit_rate_hz']:g} Hz" if any(r["decimation"] > 1 for r in
                                                                           sampling["train"]) else "")
           + (f" and cut to {sampling['max_fit_samples']} rows in total (max_fit_samples)" if sampling["capped"]
              else "") + f": {part(sampling['train'], sampling['capped'])}")
    held = (f"held-out error on {sampling['holdout_rows_used']} of {sampling['holdout_rows']} rows"
            + (f", decimated to about {sampling['fit_rate_hz']:g} Hz" if any(r["decimation"] > 1 for r in
                                                                            sampling["holdout"]) else "")
            + f": {part(sampling['holdout'], False)}")
    return [fit, held]


def _signature_lines(signature: dict) -> list[str]:
    def number(value, unit="mm") -> str:
        return "-" if value is None else f"{value:.3f} {unit}".strip()

    rate = signature["rate_dependence"]
    band = signature["dead_band"]
    lines = [f"- rate dependence: loop width error {', '.join(number(v) for v in rate['loop_width_error_mm'])} "
             f"in the speed bins {rate['speed_bins_mm_s']} mm/s; slope {number(rate['slope_mm_per_mm_s'], 'mm per mm/s')}",
             f"- dead band after reversals ({band['reversals']}): measured {number(band['measured_mm'])}, "
             f"model {number(band['model_mm'])}, excess {number(band['excess_mm'])} of tendon travel",
             f"- static holds: bias {number(signature['static_hold']['bias_mm'])}, "
             f"RMSE {number(signature['static_hold']['rmse_mm'])}",
             f"- zero load: bias {number(signature['zero_load']['bias_mm'])}, correlation with free length "
             f"{number(signature['zero_load']['corr_free_length'], '')}",
             f"- out of plane: RMSE {number(signature['out_of_plane']['rmse_mm'])}, share "
             f"{number(signature['out_of_plane']['share'], '')}, correlation with articulation "
             f"{number(signature['out_of_plane']['corr_articulation'], '')}",
             "- correlation of |error| with " + ", ".join(f"{k.replace('_', ' ')} {number(v, '')}"
                                                          for k, v in signature["correlations"].items())]
    return lines
