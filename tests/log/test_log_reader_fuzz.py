"""Fuzzing the log reader: any bytes give a valid ExperimentLog or a LogFormatError, nothing else."""

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from crest.log import ExperimentLog, LogFormatError, LogWriter, TruncatedLogWarning, catheter_dict, read_log

FUZZ = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])


@pytest.fixture(scope="module")
def valid_log(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("fuzz_log") / "valid.csv"
    with LogWriter(path, catheter=catheter_dict(flexible_length_mm=80, tendon_offset_mm=2.5, outer_diameter_mm=6),
                   sample_rate_hz=100.0, source="fuzz", tendon_force=True) as writer:
        for row in range(20):
            writer.write(row * 0.01, [row * 0.1, 0, -row * 0.1, 0], 50, [row * 0.1, 0, -row * 0.1, 0], 50,
                         None if row % 7 == 3 else [row * 0.5, 0, 79], tendon_force_n=[1, 2, 3, 4])
    return path


def _read(path: Path) -> ExperimentLog | None:
    """The log, or None after a LogFormatError that names the file; anything else fails the test."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TruncatedLogWarning)
        try:
            log = read_log(path)
        except LogFormatError as error:
            assert str(path.parent) in str(error)
            return None
    assert np.all(np.diff(log.t_s) > 0)
    assert np.all(np.isfinite(log.tendon_cmd_mm)) and np.all(np.isfinite(log.insertion_cmd_mm))
    # a position is a number or empty (NaN: the drive did not answer), never infinite
    assert not np.any(np.isinf(log.tendon_pos_mm)) and not np.any(np.isinf(log.insertion_pos_mm))
    if log.tendon_force_n is not None:                        # no force without its position
        assert np.all(np.isnan(log.tendon_force_n)[np.isnan(log.tendon_pos_mm)])
    return log


@FUZZ
@given(cut=st.integers(min_value=0, max_value=3000))
def test_truncated_log_reads_a_prefix_or_fails_clearly(valid_log: Path, cut: int):
    body = valid_log.read_bytes()
    path = valid_log.with_name("cut.csv")
    path.write_bytes(body[:cut])
    path.with_suffix(".json").write_bytes(valid_log.with_suffix(".json").read_bytes())
    log = _read(path)
    if log is not None:
        full = read_log(valid_log)
        np.testing.assert_array_equal(log.tip_mm, full.tip_mm[:len(log)])


@FUZZ
@given(position=st.integers(min_value=0, max_value=3000), noise=st.binary(min_size=1, max_size=8))
def test_corrupted_body_reads_or_fails_clearly(valid_log: Path, position: int, noise: bytes):
    body = valid_log.read_bytes()
    position %= len(body)
    path = valid_log.with_name("corrupt.csv")
    path.write_bytes(body[:position] + noise + body[position + len(noise):])
    path.with_suffix(".json").write_bytes(valid_log.with_suffix(".json").read_bytes())
    _read(path)


@FUZZ
@given(body=st.binary(max_size=200), sidecar=st.binary(max_size=80))
def test_random_bytes_fail_clearly(valid_log: Path, body: bytes, sidecar: bytes):
    path = valid_log.with_name("random.csv")
    path.write_bytes(body)
    path.with_suffix(".json").write_bytes(sidecar)
    assert _read(path) is None


JSON_VALUES = st.recursive(st.none() | st.booleans() | st.floats(allow_nan=False) | st.integers() | st.text(max_size=5),
                           lambda children: st.lists(children, max_size=4)
                           | st.dictionaries(st.text(max_size=5), children, max_size=4), max_leaves=8)


@FUZZ
@given(key=st.sampled_from(["format", "catheter", "sample_rate_hz", "source", "notes", "flexible_length_mm",
                            "outer_diameter_mm", "tendon_offset_mm", "tendon_angles_deg"]), value=JSON_VALUES)
def test_mutated_sidecar_reads_or_fails_clearly(valid_log: Path, key: str, value):
    sidecar = json.loads(valid_log.with_suffix(".json").read_text())
    (sidecar if key in sidecar else sidecar["catheter"])[key] = value
    path = valid_log.with_name("mutated.csv")
    path.write_bytes(valid_log.read_bytes())
    path.with_suffix(".json").write_text(json.dumps(sidecar))
    _read(path)
