"""Several stored blind-benchmark results scored as one: every case of the given `crest gap
--blind-benchmark --json` files, per plant family, through the benchmark's own `score`.

Each seed's run scores its own cases; the README's tables add seeds together. Scoring the
union of their cases (not averaging their scores) gives the counts a reader can check:
`crest gap --combine docs/blind_benchmark_rod/seed*/blind.json`.
"""
from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

from crest.gap.blind_benchmark import score


class BlindResultError(ValueError):
    """A file that is not a stored blind-benchmark result."""


def load_cases(path: Path) -> list[dict]:
    """The case rows of one stored result; BlindResultError naming the file if it is not one."""
    try:
        result = json.loads(Path(path).read_text())
    except OSError as error:
        raise BlindResultError(f"{path}: cannot read it ({error.strerror or error})") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as error:
        raise BlindResultError(f"{path}: not JSON ({error})") from None
    cases = result.get("cases") if isinstance(result, dict) else None
    if not isinstance(cases, list) or not all(isinstance(row, dict) and "family" in row and "truth" in row
                                              and "kind" in row for row in cases):
        raise BlindResultError(f"{path}: not a blind-benchmark result (`crest gap --blind-benchmark --json`): "
                               "it needs a list 'cases' of rows with 'family', 'kind' and 'truth'")
    return cases


def combined_result(paths: Sequence[Path]) -> dict:
    """{"combined": the files, "score": {family: score of the union of its cases over every file}
    (families in first-seen order), "cases": every case row}: the shape of a blind-benchmark result,
    so that its report can be written as one run's is. Every file is read before anything is scored,
    so a bad one fails the whole call."""
    if not paths:
        raise BlindResultError("give at least one stored blind-benchmark result (blind.json)")
    rows = [row for path in paths for row in load_cases(path)]
    by_family: dict[str, list[dict]] = {}
    for row in rows:
        by_family.setdefault(row["family"], []).append(row)
    return {"combined": [str(path) for path in paths],
            "score": {family: score(family_rows) for family, family_rows in by_family.items()}, "cases": rows}
