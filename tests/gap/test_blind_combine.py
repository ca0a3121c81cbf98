"""`crest gap --combine`: stored blind-benchmark results scored together, run as a user runs it."""
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
STORED = [ROOT / "docs" / "blind_benchmark_rod" / f"seed{seed}" / "blind.json" for seed in (77, 78)]


def crest(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "crest.cli.main", "gap", *args], cwd=cwd, capture_output=True,
                          text=True, timeout=300)


def test_combined_seeds_count_every_case_of_each_seed(tmp_path):
    out = tmp_path / "combined.json"
    done = crest("--combine", *map(str, STORED), "--json", str(out), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    combined = json.loads(out.read_text())["score"]["rod"]
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


def test_a_file_that_is_not_a_blind_result_is_refused_by_name_and_nothing_is_written(tmp_path):
    log = tmp_path / "gap.json"
    log.write_text(json.dumps({"verdict": {"effect": "none"}}))
    out = tmp_path / "combined.json"
    done = crest("--combine", str(STORED[0]), str(log), "--json", str(out), cwd=tmp_path)
    assert done.returncode != 0
    assert f"{log}: not a blind-benchmark result" in done.stderr
    assert not out.exists()
