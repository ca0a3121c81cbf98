"""`crest gap --combine`: stored blind-benchmark results scored together, and their report, run as a user runs it."""
import json
import subprocess
import sys
from pathlib import Path

from crest.gap.blind_benchmark import ALL_EFFECTS
from crest.gap.miss_causes import CAUSE_WORDS, CAUSES

ROOT = Path(__file__).resolve().parents[2]
STORED = [ROOT / "docs" / "blind_benchmark_rod" / f"seed{seed}" / "blind.json" for seed in (77, 78)]


def crest(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "crest.cli.main", "gap", *args], cwd=cwd, capture_output=True,
                          text=True, timeout=300)


def test_combined_seeds_count_every_case_of_each_seed(tmp_path):
    out = tmp_path / "combined.json"
    report = tmp_path / "report"
    done = crest("--combine", *map(str, STORED), "--json", str(out), "--report", str(report), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    result = json.loads(out.read_text())
    combined = result["score"]["rod"]
    assert len(result["cases"]) == sum(len(json.loads(path.read_text())["cases"]) for path in STORED)
    # the report, as one run's: its Markdown names the stored files, its figures are there
    assert f"report written to {report / 'blind_benchmark.md'}" in done.stdout
    assert all(str(path) in (report / "blind_benchmark.md").read_text() for path in STORED)
    assert all((report / name).stat().st_size > 0 for name in ("detection_rod.png", "confusion_rod.png", "shrink.png"))
    seeds = [json.loads(path.read_text())["score"]["rod"] for path in STORED]

    def hits(score: dict, fraction: str, count: str) -> int:
        return round(score[fraction] * score["counts"][count])

    for fraction, count in (("top1_single_above_detection", "single_above_detection"),
                            ("no_catalog_effect_clean", "none"), ("unexplained_out_of_catalog", "out_of_catalog")):
        assert combined["counts"][count] == sum(s["counts"][count] for s in seeds)
        assert hits(combined, fraction, count) == sum(hits(s, fraction, count) for s in seeds)
    total = combined["counts"]["single_above_detection"]
    assert f"top-1 above the detection limit: {hits(combined, 'top1_single_above_detection', 'single_above_detection')} " \
           f"of {total}" in done.stdout
    assert "the true effect ranked first among the candidates" in done.stdout
    # every miss above the detection limit is put down to one cause, on stdout and in the report
    misses = combined["misses_above_detection"]
    missed = total - hits(combined, "top1_single_above_detection", "single_above_detection")
    assert sum(misses[cause] for cause in CAUSES) == missed > 0
    line = next(text for text in done.stdout.splitlines() if text.startswith("misses above the detection limit"))
    assert all(f"{misses[cause]} {CAUSE_WORDS[cause]}" in line for cause in CAUSES if misses[cause])
    assert f"| all effects | {' | '.join(str(misses[cause]) for cause in CAUSES)} |" in \
        (report / "blind_benchmark.md").read_text()
    # the detection-limit curve pooled over every effect holds each effect's cases, bin by bin
    for curve, title in (("detection_curve", "top-1 by the effect's size"),
                         ("visible_detection_curve", "top-1 by the visible part")):
        pooled = {row["ratio_low"]: row for row in combined[curve][ALL_EFFECTS]}
        per_effect = [row for effect_id, bins in combined[curve].items() if effect_id != ALL_EFFECTS for row in bins]
        for low, row in pooled.items():
            inside = [r for r in per_effect if r["ratio_low"] == low]
            assert row["cases"] == sum(r["cases"] for r in inside)
            assert round(row["top1"] * row["cases"]) == sum(round(r["top1"] * r["cases"]) for r in inside)
        line = next(text for text in done.stdout.splitlines() if text.startswith(title))
        assert all(f"{row['cases']} (" in line for row in pooled.values())


def test_a_file_that_is_not_a_blind_result_is_refused_by_name_and_nothing_is_written(tmp_path):
    log = tmp_path / "gap.json"
    log.write_text(json.dumps({"verdict": {"effect": "none"}}))
    out = tmp_path / "combined.json"
    done = crest("--combine", str(STORED[0]), str(log), "--json", str(out), cwd=tmp_path)
    assert done.returncode != 0
    assert f"{log}: not a blind-benchmark result" in done.stderr
    assert not out.exists()
