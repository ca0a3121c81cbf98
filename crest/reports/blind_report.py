"""The blind-benchmark report: Markdown and PNG (`crest gap --blind-benchmark --report DIR`).

- blind_benchmark.md: per plant family the scores against their targets, the confusion matrix
  (true effect -> verdict: single, clean and out-of-catalog cases), the detection-limit table,
  the misses above the detection limit by cause (`crest.gap.miss_causes`), and one line per case;
- confusion_<family>.png: the confusion matrix as a heat map;
- detection_<family>.png: top-1 per effect against the effect's size relative to the baseline
  residual (the detection-limit curve); on the rod family also against the effect's visible part
  (`crest.gap.visible_effect`);
- shrink.png: the predicted shrink against the oracle shrink, one point per case with an effect.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from crest.gap.blind_benchmark import ALL_EFFECTS
from crest.gap.miss_causes import CAUSE_WORDS, CAUSES
from crest.paper.figure_output import new_figure, save_png


def write_blind_report(result: dict, out_dir: Path | str) -> Path:
    """Write blind_benchmark.md and the figures into out_dir (created); returns the Markdown path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    for family, score in result["score"].items():
        save_png(_confusion_figure(score["confusion"]), out / f"confusion_{family}.png")
        save_png(_detection_figure(score["detection_curve"], score.get("visible_detection_curve")),
                 out / f"detection_{family}.png")
    save_png(_shrink_figure(result["cases"]), out / "shrink.png")
    path = out / "blind_benchmark.md"
    path.write_text(markdown(result))
    return path


def _used_labels(confusion: dict) -> tuple[list[str], list[str]]:
    """Rows with at least one case; columns predicted at least once or on the diagonal."""
    rows = [t for t, counts in confusion.items() if sum(counts.values())]
    columns = [p for p in next(iter(confusion.values())) if p in rows or any(confusion[t][p] for t in rows)]
    return rows, columns


def confusion_markdown(confusion: dict) -> str:
    """The confusion matrix as a Markdown table: rows the true effect, columns the verdict."""
    rows, columns = _used_labels(confusion)
    lines = ["| true \\ verdict | " + " | ".join(columns) + " |", "|---" * (len(columns) + 1) + "|"]
    for truth in rows:
        cells = [str(confusion[truth][p]) if confusion[truth][p] else "." for p in columns]
        lines.append(f"| {truth} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _pct(value: float | None) -> str:
    return "-" if value is None else f"{100 * value:.0f}%"


def markdown(result: dict) -> str:
    """One run's report (its seed and settings), or that of stored runs scored together (`combined`:
    their files)."""
    if "combined" in result:
        source = f"Stored results scored together (`crest gap --combine`): {', '.join(result['combined'])}."
    else:
        settings = result["settings"]
        source = (f"Seed {settings['seed']}, {settings['excitation']} excitation, {settings['path']}; "
                  f"{settings['seconds'] / 60:.0f} min.")
    lines = ["# Blind benchmark of the gap diagnosis", "", source, ""]
    for family, score in result["score"].items():
        lines += _family_markdown(family, score)
    lines += ["## Cases", "",
              "| family | case | truth | verdict | effect size mm | size / residual | visible / residual | noise mm | "
              "shrink | oracle |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    for row in result["cases"]:
        truth = "+".join(row["truth"]) or "none"
        family = row.get("family", "dahl")
        if "predicted_shrink" not in row:
            lines.append(f"| {family} | {row['case']} | {truth} | {row.get('skipped') or row.get('no_result')} "
                         "| | | | | | |")
            continue
        oracle = f"{row['oracle_shrink']:.2f}" if _has_oracle(row) else ("failed" if "oracle_shrink" in row else "-")
        visible = f"{row['visible_relative_size']:.2f}" if "visible_relative_size" in row else "-"
        lines.append(f"| {family} | {row['case']} | {truth} | {'+'.join(row['predicted_effects']) or row['predicted']} | "
                     f"{row['effect_rms_mm']:.2f} | {row.get('relative_size', 0.0):.2f} | {visible} | {row['noise_mm']:.2f} | "
                     f"{row['predicted_shrink']:.2f} | {oracle} |")
    return "\n".join(lines) + "\n"


def _family_markdown(family: str, score: dict) -> list[str]:
    shrink = score["shrink_error_pp"] or {}
    counts = score["counts"]
    lines = [
        f"## {family} family: {score['cases']} cases", "",
        "| score | result | target |", "|---|---|---|",
        f"| top-1 on single effects | {_pct(score['top1_single'])} of {counts['single']} | - |",
        f"| top-1 above the detection limit | {_pct(score['top1_single_above_detection'])} of "
        f"{counts['single_above_detection']} | >= 90% |",
        *([f"| top-1 above the detection limit by the effect's visible part (what the calibrated model cannot absorb) | "
           f"{_pct(score['top1_single_above_visible_limit'])} of {counts['single_above_visible_limit']} | - |"]
          if counts.get("single_with_visible_size") else []),
        *([f"| the true effect ranked first among the candidates, above the detection limit (the most any verdict "
           f"rule could name) | {_pct(score['truth_ranked_first_above_detection'])} of "
           f"{counts['single_above_detection_with_candidates']} | - |"]
          if counts.get("single_above_detection_with_candidates") else []),
        f"| top-1 where the effect moves the tip more than the tracker noise | "
        f"{_pct(score['top1_single_above_noise'])} of {counts['single'] - counts['single_below_noise']} | - |",
        f"| clean cases with no catalog effect (`none` or `unexplained`) | {_pct(score['no_catalog_effect_clean'])} "
        f"of {counts['none']} | >= 80% |",
        f"| `none` on clean cases | {_pct(score['none_clean'])} of {counts['none']} | - |",
        f"| `confident` verdicts above the detection limit: right / wrong | "
        f"{score['confident_single_above_detection']['right']} / {score['confident_single_above_detection']['wrong']} "
        f"| - / 0 |",
        f"| clean cases with a catalog effect named `confident` | {score['confident_catalog_effect_clean']} | 0 |"]
    if counts["out_of_catalog"]:
        lines += [f"| `unexplained` on out-of-catalog cases | {_pct(score['unexplained_out_of_catalog'])} of "
                  f"{counts['out_of_catalog']} | >= 80% |",
                  f"| out-of-catalog cases with a catalog effect named | {score['catalog_effect_out_of_catalog']} | 0 |",
                  f"| out-of-catalog cases with a catalog effect named `confident` (it at least halves the report "
                  f"half's error above the noise floor) | {score['confident_catalog_effect_out_of_catalog']} | 0 |"]
    if counts["pair"]:
        lines.append(f"| pairs: exact / at least one found | {_pct(score['pair_exact'])} / "
                     f"{_pct(score['pair_any_found'])} of {counts['pair']} | - |")
    lines += [f"| predicted shrink vs oracle, mean error (cases with an effect: {shrink.get('cases', 0)}) | "
              f"{shrink.get('mean', float('nan')):.1f} pp (median {shrink.get('median', float('nan')):.1f}, "
              f"max {shrink.get('max', float('nan')):.1f}) | <= 10 pp |",
              "", f"Skipped (no plant could be recorded): {counts['skipped']}; no result: {counts['no_result']}.", "",
              "### Confusion matrix (single, clean and out-of-catalog cases)", "",
              confusion_markdown(score["confusion"]), "",
              "### Detection limit: top-1 against effect size / baseline residual", "",
              f"![detection limit](detection_{family}.png)", "",
              "| effect | size / residual | cases | top-1 |", "|---|---|---|---|"]
    lines += _curve_rows(score["detection_curve"])
    if counts.get("single_with_visible_size"):
        lines += ["", "By the effect's visible part (the detection figure's right panel):", "",
                  "| effect | visible / residual | cases | top-1 |", "|---|---|---|---|"]
        lines += _curve_rows(score["visible_detection_curve"])
    return lines + ["", *_miss_rows(score["misses_above_detection"])]


def _miss_rows(misses: dict) -> list[str]:
    """The misses above the detection limit per true effect and cause (`crest.gap.miss_causes`)."""
    if not misses["by_effect"]:
        return []
    lines = ["### Misses above the detection limit, by cause", "",
             *(f"- {cause}: {CAUSE_WORDS[cause]}" for cause in CAUSES), "",
             "| effect | " + " | ".join(CAUSES) + " |", "|---" * (len(CAUSES) + 1) + "|"]
    for effect_id, causes in misses["by_effect"].items():
        lines.append(f"| {effect_id} | " + " | ".join(str(causes.get(cause, 0)) for cause in CAUSES) + " |")
    lines.append("| all effects | " + " | ".join(str(misses[cause]) for cause in CAUSES) + " |")
    if misses.get("truth_as_good"):
        lines += ["", f"In {misses['truth_as_good']} of these misses the verdict listed the true effect as good "
                      "on these logs: a tie the logs cannot break."]
    return lines + [""]


def _curve_rows(curve: dict) -> list[str]:
    lines = []
    for effect_id, bins in curve.items():
        for row in bins:
            high = "inf" if row["ratio_high"] is None else f"{row['ratio_high']:g}"
            lines.append(f"| {effect_id} | {row['ratio_low']:g}-{high} | {row['cases']} | {_pct(row['top1'])} |")
    return lines


def _detection_figure(curve: dict, visible_curve: dict | None = None) -> Figure:
    """Top-1 against the effect's raw size; beside it, where known (rod), against its visible part."""
    panels = [(curve, "effect size / baseline residual (held-out RMS)")]
    if visible_curve and any(visible_curve.values()):
        panels.append((visible_curve, "visible part / baseline residual"))
    figure = new_figure(6.0 * len(panels), 4.0)
    for ax, (bins_by_effect, label) in zip(np.atleast_1d(figure.subplots(1, len(panels))), panels):
        for effect_id, bins in bins_by_effect.items():
            if bins:
                centres = [(row["ratio_low"] + (row["ratio_high"] if row["ratio_high"] is not None
                                                else 1.5 * max(row["ratio_low"], 1.0))) / 2 for row in bins]
                pooled = {"color": "black", "linewidth": 2.5} if effect_id == ALL_EFFECTS else {}
                ax.plot(centres, [row["top1"] for row in bins], marker="o", label=effect_id, **pooled)
        ax.set_xlabel(label)
        ax.set_ylabel("top-1")
        ax.set_ylim(-0.05, 1.05)
        if bins_by_effect:
            ax.legend(fontsize=7)
    return figure


def _confusion_figure(confusion: dict) -> Figure:
    rows, columns = _used_labels(confusion)
    counts = np.array([[confusion[t][p] for p in columns] for t in rows], dtype=float)
    figure = new_figure(1.2 + 0.6 * len(columns), 1.0 + 0.45 * len(rows))
    ax = figure.subplots()
    ax.imshow(counts, cmap="Blues")
    ax.set_xticks(range(len(columns)), columns, rotation=45, ha="right")
    ax.set_yticks(range(len(rows)), rows)
    for (i, j), count in np.ndenumerate(counts):
        if count:
            ax.text(j, i, f"{count:.0f}", ha="center", va="center", color="black" if count < counts.max() / 2
                    else "white")
    ax.set_xlabel("verdict")
    ax.set_ylabel("true effect")
    return figure


def _has_oracle(row: dict) -> bool:
    """The case has an oracle shrink to compare with: not where the oracle's held-out prediction
    failed (-inf in the run, null in its JSON)."""
    return row.get("oracle_shrink") is not None and bool(np.isfinite(row["oracle_shrink"]))


def _shrink_figure(cases: list[dict]) -> Figure:
    figure = new_figure(5.0, 4.6)
    ax = figure.subplots()
    scored = [r for r in cases if _has_oracle(r)]
    hit = [r for r in scored if sorted(r["predicted_effects"]) == sorted(r["truth"])]
    miss = [r for r in scored if r not in hit]
    for rows, label, color in ((hit, "verdict right", "tab:green"), (miss, "verdict wrong", "tab:red")):
        ax.scatter([r["oracle_shrink"] for r in rows], [r["predicted_shrink"] for r in rows], s=18, color=color,
                   label=label)
    low = min([-0.05] + [min(r["oracle_shrink"], r["predicted_shrink"]) for r in scored])
    ax.plot([low, 1], [low, 1], color="grey", linewidth=0.8)
    ax.fill_between([low, 1], [low - 0.1, 0.9], [low + 0.1, 1.1], color="grey", alpha=0.15, label="within 10 pp")
    ax.set_xlim(low, 1.0)
    ax.set_ylim(low, 1.0)
    ax.set_xlabel("oracle shrink (true effects added and calibrated)")
    ax.set_ylabel("predicted shrink")
    ax.legend(loc="upper left")
    return figure
