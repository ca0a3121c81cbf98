"""Fuzzing the configuration loader: any input gives a TestbedConfig or one ConfigError, nothing else."""

import copy
import shutil
import tomllib
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from crest.config import ConfigError, TestbedConfig, load_testbed_config, parse_testbed_config
from crest.config.testbed_config import default_config_path

FUZZ = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])


@pytest.fixture(scope="module")
def config_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    directory = tmp_path_factory.mktemp("fuzz_config")
    shutil.copy(default_config_path(), directory / "testbed.toml")
    (directory / "crest_drive.eds").write_text("[FileInfo]\n")
    return directory


TOML_PIECES = st.sampled_from([
    "[bus]", "[sync]", "[[axes]]", "[axis_defaults.tendon]", "interface", "=", '"virtual"', "0x6040", "1e400",
    "nan", "inf", "-", "[", "]", "{", "}", ",", "\n", " ", '"', "'", "#", "period_s", "node_id", "true", "1979-05-27",
    "name = \"tendon1\"", "soft_limits_mm = [", "\\u00e9", "\x00", "\xff", ".", "[[axes]]\nname =",
])


@FUZZ
@given(pieces=st.lists(TOML_PIECES, max_size=40), raw=st.binary(max_size=60))
def test_random_toml_ish_bytes_raise_only_config_error(config_dir: Path, pieces: list[str], raw: bytes):
    path = config_dir / "fuzz.toml"
    path.write_bytes("".join(pieces).encode("utf-8", "surrogatepass") + raw)
    with pytest.raises(ConfigError) as raised:
        load_testbed_config(path)
    assert str(path) in str(raised.value)


@FUZZ
@given(cut=st.integers(min_value=0, max_value=4000))
def test_truncated_config_raises_only_config_error(config_dir: Path, cut: int):
    text = (config_dir / "testbed.toml").read_bytes()
    path = config_dir / "truncated.toml"
    path.write_bytes(text[:cut])
    try:
        load_testbed_config(path)
    except ConfigError as error:
        assert str(path) in str(error)


def _leaves(node, prefix=()):
    """Every (path, value) in nested dicts and lists, containers included."""
    yield prefix, node
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _leaves(value, prefix + (key,))
    elif isinstance(node, list):
        for index, value in enumerate(node):
            yield from _leaves(value, prefix + (index,))


ANY_VALUE = st.recursive(
    st.none() | st.booleans() | st.integers(min_value=-2**70, max_value=2**70) | st.floats()
    | st.text(max_size=8),
    lambda children: st.lists(children, max_size=4) | st.dictionaries(st.text(max_size=6), children, max_size=3),
    max_leaves=6,
)


@FUZZ
@given(choices=st.lists(st.tuples(st.integers(min_value=0), ANY_VALUE, st.booleans()), min_size=1, max_size=3))
def test_random_field_mutations_raise_only_config_error(config_dir: Path, choices):
    data = tomllib.loads((config_dir / "testbed.toml").read_text())
    for pick, value, delete in choices:
        leaves = list(_leaves(data))[1:]
        if not leaves:
            break
        path, _ = leaves[pick % len(leaves)]
        parent = data
        for key in path[:-1]:
            parent = parent[key]
        if delete:
            del parent[path[-1]]
        else:
            parent[path[-1]] = copy.deepcopy(value)
    try:
        config = parse_testbed_config(data, config_dir / "testbed.toml")
    except ConfigError as error:
        assert error.field or error.expected
    else:
        assert isinstance(config, TestbedConfig)
        assert sorted(axis.name for axis in config.axes) == ["insertion", "tendon1", "tendon2", "tendon3", "tendon4"]
