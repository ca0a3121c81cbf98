"""The real-data table: every real log held out once, with calibrated constant curvature, calibrated
Dahl and Dahl plus the diagnosis' verdict side by side.

The logs of ../shared/data/continuum_nathan (PROVENANCE.md; all rights reserved by their authors,
read at run time, never copied into the repository) are imported into crest logs in a temporary
folder (`crest.importers.continuum_nathan.import_all`), sorted by name and dealt into two folds,
alternately. Each fold is held out once while the diagnosis (`crest.gap.log_diagnosis`) trains on
the other (two-fold cross-validation over files), so every file gets a held-out RMSE of each model:

    constant curvature  calibrated on the training fold (moment arm and tendon zeros),
    Dahl                the diagnosis' calibrated baseline,
    Dahl + verdict      the baseline with the verdict's effects fitted (the baseline where the verdict
                        is `none` or `unexplained`).

The held-out RMSE is taken on every evaluated row of the file. The verdict's effect was selected on
the even time blocks of the held-out fold (`model.gap.holdout_split`), so the Dahl + verdict figure
of a file includes the rows the selection saw; the diagnosis' own shrink is on the other half.
"""
from __future__ import annotations

import tempfile
import warnings
from collections.abc import Callable
from concurrent.futures import Executor
from pathlib import Path

from crest.gap.log_diagnosis import diagnose_logs
from crest.gap.log_recordings import load_recordings
from crest.gap.real_bench_log import real_data_missing
from crest.importers.continuum_nathan import default_data_dir, import_all
from crest.reports.gap_report import write_gap_report
from model.gap.diagnosis import DiagnosisSettings

FORMAT = "crest-real-data-table/1"
FOLDS = 2


def folds(paths: list[Path]) -> list[list[Path]]:
    """The logs sorted by name and dealt alternately into FOLDS folds."""
    ordered = sorted(paths, key=lambda path: path.name)
    return [ordered[k::FOLDS] for k in range(FOLDS)]


def real_data_table(data_dir: Path | None, settings: DiagnosisSettings, progress: Callable[[str], None],
                    executor: Executor | None = None, report_dir: Path | None = None) -> dict:
    """Import the real data, diagnose each fold held out against the other, and tabulate per file;
    with report_dir, each fold's gap report (`crest gap --report`) goes to report_dir/fold_K.

    Returns {"format", "data_dir", "rows": [{"recording", "fold", "trained_on", "constant_curvature_mm",
    "dahl_mm", "dahl_verdict_mm", "verdict", "confidence"}], "diagnoses": [the diagnosis result of each fold]}.
    """
    folder = Path(data_dir) if data_dir else default_data_dir()
    missing = real_data_missing(folder)
    if missing:
        raise FileNotFoundError(missing)
    rows, diagnoses = [], []
    with tempfile.TemporaryDirectory(prefix="crest-real-data-") as tmp:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")     # the importer's notes on rejected tracker samples
            paths = import_all(folder, tmp)
        split = folds(paths)
        for k, held in enumerate(split):
            train = [path for other, fold in enumerate(split) if other != k for path in fold]
            progress(f"fold {k + 1}/{len(split)}: training on {', '.join(p.stem for p in train)}; "
                     f"holding out {', '.join(p.stem for p in held)}")
            result = diagnose_logs(train, held, settings=settings, executor=executor,
                                   progress=lambda message, k=k: progress(f"fold {k + 1}: {message}"))
            diagnoses.append(result)
            if report_dir is not None:
                write_gap_report(result, load_recordings(held), Path(report_dir) / f"fold_{k + 1}")
            for row in result["holdout_by_recording"]:
                rows.append({"recording": Path(row["recording"]).stem, "fold": k + 1,
                             "trained_on": [p.stem for p in train],
                             "constant_curvature_mm": row["constant_curvature_mm"], "dahl_mm": row["baseline_mm"],
                             "dahl_verdict_mm": row["verdict_mm"], "verdict": result["verdict"]["effect"],
                             "confidence": result["verdict"]["confidence"]})
    return {"format": FORMAT, "data_dir": str(folder), "rows": sorted(rows, key=lambda row: row["recording"]),
            "diagnoses": diagnoses}


def table_markdown(table: dict) -> str:
    """The per-file table (Markdown)."""
    lines = ["| held-out file | fold | calibrated CC | calibrated Dahl | Dahl + verdict | verdict |",
             "|---|---|---|---|---|---|"]
    for row in table["rows"]:
        lines.append(f"| {row['recording']} | {row['fold']} | {row['constant_curvature_mm']:.2f} mm | "
                     f"{row['dahl_mm']:.2f} mm | {row['dahl_verdict_mm']:.2f} mm | {row['verdict']}"
                     + (f" ({row['confidence']}) |" if row["confidence"] else " |"))
    return "\n".join(lines)
