"""The blind-benchmark report: Markdown and PNG (`crest gap --blind-benchmark --report DIR`).

- blind_benchmark.md: the scores against their targets, the confusion matrix (true effect ->
  verdict, single and clean cases), and one line per case;
- confusion.png: the confusion matrix as a heat map;
- shrink.png: the predicted shrink against the oracle shrink, one point per case.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from crest.paper.figure_output import new_figure, save_png


def write_blind_report(result: dict, out_dir: Path | str) -> Path:
    """Write blind_benchmark.md and the figures into out_dir (created); returns the Markdown path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    save_png(_confusion_figure(result["score"]["confusion"]), out / "confusion.png")
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
    score, settings = result["score"], result["settings"]
    shrink = score["shrink_error_pp"] or {}
    counts = score["counts"]
    lines = [
        "# Blind benchmark of the gap diagnosis", "",
        f"{score['cases']} cases, seed {settings['seed']}, {settings['excitation']} excitation, "
        f"{settings['path']}; {settings['seconds'] / 60:.0f} min.", "",
        "| score | result | target |", "|---|---|---|",
        f"| top-1 on single effects | {_pct(score['top1_single'])} of {counts['single']} | >= 90% |",
        f"| top-1 where the effect moves the tip more than the tracker noise | "
        f"{_pct(score['top1_single_above_noise'])} of {counts['single'] - counts['single_below_noise']} | - |",
        f"| `none` on clean cases | {_pct(score['none_clean'])} of {counts['none']} | >= 80% |",
        f"| pairs: exact / at least one found | {_pct(score['pair_exact'])} / {_pct(score['pair_any_found'])} "
        f"of {counts['pair']} | - |",
        f"| predicted shrink vs oracle, mean error | {shrink.get('mean', float('nan')):.1f} pp "
        f"(median {shrink.get('median', float('nan')):.1f}, max {shrink.get('max', float('nan')):.1f}) | <= 10 pp |",
        "", f"Skipped (no plant could be recorded): {counts['skipped']}; no result: {counts['no_result']}.", "",
        "## Confusion matrix (single and clean cases)", "", confusion_markdown(score["confusion"]), "",
        "## Cases", "",
        "| case | truth | verdict | effect size mm | noise mm | shrink | oracle |", "|---|---|---|---|---|---|---|"]
    for row in result["cases"]:
        truth = "+".join(row["truth"]) or "none"
        if "predicted_shrink" not in row:
            lines.append(f"| {row['case']} | {truth} | {row.get('skipped') or row.get('no_result')} | | | | |")
            continue
        lines.append(f"| {row['case']} | {truth} | {'+'.join(row['predicted_effects']) or 'none'} | "
                     f"{row['effect_rms_mm']:.2f} | {row['noise_mm']:.2f} | {row['predicted_shrink']:.2f} | "
                     f"{row['oracle_shrink']:.2f} |")
    return "\n".join(lines) + "\n"


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


def _shrink_figure(cases: list[dict]) -> Figure:
    figure = new_figure(5.0, 4.6)
    ax = figure.subplots()
    scored = [r for r in cases if "predicted_shrink" in r]
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
