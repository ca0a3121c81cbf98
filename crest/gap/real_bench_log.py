"""The real benchmark log: the longest log of the continuum robot data in ../shared/data, if it is there.

The data (../shared/data/continuum_nathan, see its PROVENANCE.md; all rights reserved by its
authors, read at run time, never copied into the repository) is converted with
`crest.importers.continuum_nathan.import_all` into crest logs in a temporary folder. The longest
log (most rows; on a tie the first in the importer's list) is the training log, the next longest
the held-out log: multi_sweep (1024 static poses, the sweep circle counter-clockwise) and
multi_sweep_backwards (the same commands clockwise), the pair the README's real-data diagnosis uses.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

from crest.importers.continuum_nathan import default_data_dir, import_all
from crest.log import read_log


@dataclass(frozen=True)
class RealLogs:
    train: Path
    holdout: Path
    train_rows: int
    holdout_rows: int
    import_warnings: int     # tracker samples the importer rejected (written as missing)


def real_data_missing(data_dir: Path | None = None) -> str | None:
    """Why the real benchmark cannot run (the folder is absent), or None."""
    folder = Path(data_dir) if data_dir else default_data_dir()
    if not (folder / "PROVENANCE.md").exists():
        return f"no real data at {folder} (the continuum_nathan folder of ../shared/data, with PROVENANCE.md)"
    return None


def real_logs(out_dir: Path, data_dir: Path | None = None) -> RealLogs:
    """Import the data into out_dir and pick the training and held-out logs (see module doc)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        paths = import_all(Path(data_dir) if data_dir else default_data_dir(), out_dir)
    rows = {path: len(read_log(path).t_s) for path in paths}
    train, holdout = sorted(paths, key=lambda path: -rows[path])[:2]     # a stable sort keeps the list's order
    return RealLogs(train, holdout, rows[train], rows[holdout], len(caught))
