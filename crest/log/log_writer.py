"""Append-only writer of crest-log/1 experiment logs (CSV body + JSON sidecar, see log_format).

Durability: rows are collected in memory and written as whole lines, then ``os.fsync``-ed, as soon
as the unwritten rows span ``flush_interval_s`` of log time (t) or that much wall time has passed
since the last flush. A killed process therefore leaves a readable log that lacks at most the
last flush interval (0.5 s by default). The sidecar is written at open (atomically) and rewritten
at close with a ``summary`` (and again if the summary is amended after close).
"""

from __future__ import annotations

import json
import math
import os
import platform
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from datetime import datetime, timezone
from importlib import metadata
from pathlib import Path
from types import TracebackType
from typing import Any

from crest.log.log_format import (
    FORMAT_TAG,
    INSERTION_CMD_COLUMN,
    INSERTION_POS_COLUMN,
    TENDON_CMD_COLUMNS,
    TENDON_FORCE_COLUMNS,
    TENDON_POS_COLUMNS,
    TIP_COLUMNS,
    TIP_REF_COLUMNS,
    check_sidecar,
    header_columns,
    sidecar_path,
    units_of,
)

DEFAULT_FLUSH_INTERVAL_S = 0.5


def software_version() -> str:
    """The installed crest-hil version, or "unknown" when running from an uninstalled tree."""
    try:
        return metadata.version("crest-hil")
    except metadata.PackageNotFoundError:
        return "unknown"


def _write_json_atomically(path: Path, data: Mapping[str, Any]) -> None:
    """Write JSON to a temporary file and rename it over ``path``: readers never see half a file."""
    text = json.dumps(data, indent=2, allow_nan=False) + "\n"
    temporary = path.with_name(path.name + ".tmp")
    with open(temporary, "w", encoding="utf-8") as file:
        file.write(text)
        file.flush()
        os.fsync(file.fileno())
    os.replace(temporary, path)


class LogWriter:
    """Write one experiment log: ``LogWriter(path, catheter=..., sample_rate_hz=..., source=...)``.

    ``catheter`` is the sidecar's catheter object (see `log_format.catheter_dict`); ``config`` a
    JSON-able configuration snapshot (e.g. ``TestbedConfig.as_dict()``); ``plant`` what the virtual
    testbed simulated behind the drives (`crest.backend.plant_summary`; None, and no key, on
    hardware); ``tendon_force`` and
    ``tip_ref`` add the optional column groups. An existing log is not overwritten unless
    ``overwrite`` is true. Thread-safe: a safety stop may flush or close from another thread.
    """

    def __init__(self, csv_path: Path | str, *, catheter: Mapping[str, Any], sample_rate_hz: float,
                 source: str, notes: str = "", tendon_force: bool = False, tip_ref: bool = False,
                 config: Mapping[str, Any] | None = None, plant: str | None = None, overwrite: bool = False,
                 flush_interval_s: float = DEFAULT_FLUSH_INTERVAL_S,
                 clock: Callable[[], float] = time.monotonic) -> None:
        if not (math.isfinite(flush_interval_s) and 0.0 < flush_interval_s <= DEFAULT_FLUSH_INTERVAL_S):
            raise ValueError(f"flush_interval_s must be in (0, {DEFAULT_FLUSH_INTERVAL_S}] s, got {flush_interval_s!r}")
        self.path = Path(csv_path)
        self.sidecar_path = sidecar_path(self.path)
        if self.path.suffix.lower() != ".csv":
            raise ValueError(f"{self.path}: a crest log must be a .csv file (its sidecar is the .json beside it)")
        if not overwrite:
            for existing in (self.path, self.sidecar_path):
                if existing.exists():
                    raise FileExistsError(f"{existing} already exists; choose another path or pass overwrite=True")
        self.columns = header_columns(tendon_force=tendon_force, tip_ref=tip_ref)
        self._tendon_force = tendon_force
        self._tip_ref = tip_ref
        self._flush_interval_s = flush_interval_s
        self._clock = clock
        self._lock = threading.Lock()
        self._pending: list[str] = []
        self._rows_written = 0
        self._first_t_s: float | None = None
        self._last_t_s: float | None = None
        self._flushed_t_s: float | None = None
        self._flushed_at = clock()

        self._sidecar: dict[str, Any] = {
            "format": FORMAT_TAG,
            "catheter": dict(catheter),
            "sample_rate_hz": sample_rate_hz,
            "source": source,
            "notes": notes,
            "columns": list(self.columns),
            "units": units_of(self.columns),
            "created_utc": datetime.now(timezone.utc).isoformat(timespec="seconds"),
            "software": {"crest_version": software_version(), "python": platform.python_version()},
            "config": None if config is None else dict(config),
        }
        if plant is not None:
            self._sidecar["plant"] = plant
        check_sidecar(self._sidecar, self.sidecar_path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        _write_json_atomically(self.sidecar_path, self._sidecar)
        flags = os.O_WRONLY | os.O_CREAT | (os.O_TRUNC if overwrite else os.O_EXCL)
        self._fd: int | None = os.open(self.path, flags, 0o644)
        self._size_bytes = 0
        self._size_bytes = self._write_and_sync(",".join(self.columns) + "\n")

    def write(self, t_s: float, tendon_cmd_mm: Sequence[float], insertion_cmd_mm: float,
              tendon_pos_mm: Sequence[float | None], insertion_pos_mm: float | None,
              tip_mm: Sequence[float] | None = None, *, tendon_force_n: Sequence[float | None] | None = None,
              tip_ref_mm: Sequence[float] | None = None) -> None:
        """Append one sample. ``tip_mm`` None (or all NaN) is a missing tracker sample.

        A position entry (one of ``tendon_pos_mm``, or ``insertion_pos_mm``) that is None or NaN is
        an axis whose drive did not answer this SYNC: an empty cell. A ``tendon_force_n`` entry
        None or NaN is an empty force cell (all four when ``tendon_force_n`` is None), and a tendon
        without a position must have none. t must increase strictly; t and commands must be finite,
        and positions and forces finite or missing, never infinite (ValueError otherwise).
        """
        t_s = float(t_s)
        if not math.isfinite(t_s):
            raise ValueError(f"{self.path}: t must be finite, got {t_s!r}")
        cells = [_number(t_s)]
        cells += _finite_cells(tendon_cmd_mm, TENDON_CMD_COLUMNS, self.path)
        cells += _finite_cells([insertion_cmd_mm], (INSERTION_CMD_COLUMN,), self.path)
        tendon_pos_cells = _measured_cells(tendon_pos_mm, TENDON_POS_COLUMNS, self.path)
        cells += tendon_pos_cells
        cells += _measured_cells([insertion_pos_mm], (INSERTION_POS_COLUMN,), self.path)
        cells += _optional_cells(tip_mm, TIP_COLUMNS, self.path)
        if self._tendon_force:
            force_cells = (_measured_cells(tendon_force_n, TENDON_FORCE_COLUMNS, self.path)
                           if tendon_force_n is not None else [""] * len(TENDON_FORCE_COLUMNS))
            for position, force, pos_column, force_column in zip(tendon_pos_cells, force_cells, TENDON_POS_COLUMNS,
                                                                 TENDON_FORCE_COLUMNS):
                if position == "" and force != "":
                    raise ValueError(f"{self.path}: {pos_column} is missing (no answer from the drive) but "
                                     f"{force_column} is {force}; a tendon's force comes in the same answer, "
                                     "so give NaN for both")
            cells += force_cells
        elif tendon_force_n is not None:
            raise ValueError(f"{self.path}: tendon_force_n given but the log was opened without tendon_force=True")
        if self._tip_ref:
            cells += _optional_cells(tip_ref_mm, TIP_REF_COLUMNS, self.path)
        elif tip_ref_mm is not None:
            raise ValueError(f"{self.path}: tip_ref_mm given but the log was opened without tip_ref=True")

        with self._lock:
            if self._fd is None:
                raise ValueError(f"{self.path}: the log is closed")
            if self._last_t_s is not None and t_s <= self._last_t_s:
                raise ValueError(f"{self.path}: t must increase strictly; got {t_s!r} after {self._last_t_s!r}")
            if self._first_t_s is None:
                self._first_t_s = self._flushed_t_s = t_s
            self._last_t_s = t_s
            self._pending.append(",".join(cells) + "\n")
            self._rows_written += 1
            if (t_s - self._flushed_t_s >= self._flush_interval_s
                    or self._clock() - self._flushed_at >= self._flush_interval_s):
                self._flush_locked()

    def flush(self) -> None:
        """Write the pending rows and fsync them now (e.g. on a safety stop)."""
        with self._lock:
            if self._fd is not None:
                self._flush_locked()

    def close(self, summary: Mapping[str, Any] | None = None) -> None:
        """Flush, close the CSV and rewrite the sidecar with a ``summary`` (e.g. {"stop_cause": ...}).

        The summary always holds ``samples``, ``duration_s`` and ``closed_utc``. Closing twice is a no-op.
        """
        with self._lock:
            if self._fd is None:
                return
            self._flush_locked()
            os.close(self._fd)
            self._fd = None
            self._sidecar["summary"] = {
                "samples": self._rows_written,
                "duration_s": 0.0 if self._first_t_s is None else self._last_t_s - self._first_t_s,
                "closed_utc": datetime.now(timezone.utc).isoformat(timespec="seconds"),
                **(summary or {}),
            }
            _write_json_atomically(self.sidecar_path, self._sidecar)

    def amend_summary(self, entries: Mapping[str, Any]) -> None:
        """Add ``entries`` to the closed log's summary and rewrite the sidecar.

        For what happens after the last row, e.g. a safety stop while the session is being closed.
        """
        with self._lock:
            if self._fd is not None:
                raise ValueError(f"{self.path}: the log is still open; pass the summary to close()")
            self._sidecar["summary"].update(entries)
            _write_json_atomically(self.sidecar_path, self._sidecar)

    def __enter__(self) -> LogWriter:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 traceback: TracebackType | None) -> None:
        self.close(None if exc is None else {"stop_cause": f"{type(exc).__name__}: {exc}"})

    def _flush_locked(self) -> None:
        if self._pending:
            end_bytes = self._write_and_sync("".join(self._pending))
            # No call between these two stores, so Ctrl-C or SIGTERM (whose exception Python
            # raises at a call or a loop) cannot count the rows as written but leave them pending.
            self._size_bytes, self._pending = end_bytes, []
            self._flushed_t_s = self._last_t_s
        self._flushed_at = self._clock()

    def _write_and_sync(self, text: str) -> int:
        """Write ``text`` after the bytes already counted as written, fsync; returns the new end.

        At an explicit offset, not appended: when Ctrl-C or SIGTERM interrupts a flush after the
        bytes reached the file but before they were counted, the next flush (the stop closing the
        log) writes them again at the same place, instead of a second time after them.
        """
        data = text.encode("ascii")
        offset = self._size_bytes
        while data:
            written = os.pwrite(self._fd, data, offset)
            data, offset = data[written:], offset + written
        os.fsync(self._fd)
        return offset


def _number(value: float) -> str:
    """Shortest text that reads back as the same float."""
    return repr(float(value))


def _finite_cells(values: Sequence[float] | Any, columns: Sequence[str], path: Path) -> list[str]:
    cells = _floats(values, columns, path)
    for value, column in zip(cells, columns):
        if not math.isfinite(value):
            raise ValueError(f"{path}: {column} must be a finite number, got {value!r}")
    return [_number(value) for value in cells]


def _measured_cells(values: Sequence[float | None], columns: Sequence[str], path: Path) -> list[str]:
    """One cell per value: empty where it was not measured (None or NaN), else the finite number."""
    values = list(values)
    if len(values) != len(columns):
        raise ValueError(f"{path}: expected {len(columns)} values for {', '.join(columns)}, got {len(values)}")
    cells = []
    for value, column in zip(values, columns):
        value = math.nan if value is None else float(value)
        if math.isinf(value):
            raise ValueError(f"{path}: {column} must be a finite number, or NaN/None when not measured; "
                             f"got {value!r}")
        cells.append("" if math.isnan(value) else _number(value))
    return cells


def _optional_cells(values: Sequence[float] | None, columns: Sequence[str], path: Path) -> list[str]:
    """Empty cells when the sample is missing (None or all NaN), otherwise finite numbers."""
    if values is None:
        return [""] * len(columns)
    floats = _floats(values, columns, path)
    if all(math.isnan(value) for value in floats):
        return [""] * len(columns)
    for value, column in zip(floats, columns):
        if not math.isfinite(value):
            raise ValueError(f"{path}: {column} must be finite, or all of {', '.join(columns)} missing; got {value!r}")
    return [_number(value) for value in floats]


def _floats(values: Sequence[float] | Any, columns: Sequence[str], path: Path) -> list[float]:
    floats = [float(value) for value in values]
    if len(floats) != len(columns):
        raise ValueError(f"{path}: expected {len(columns)} values for {', '.join(columns)}, got {len(floats)}")
    return floats
