"""The testbed configuration loader: the shipped file loads, every kind of bad field is named."""

import copy
import math
import shutil
import tomllib
from pathlib import Path

import pytest

from crest.config import ConfigError, load_testbed_config, parse_testbed_config
from crest.config.testbed_config import default_config_path

SHIPPED = default_config_path()


@pytest.fixture
def config_dir(tmp_path: Path) -> Path:
    """A copy of the shipped config with an EDS beside it, to edit freely."""
    shutil.copy(SHIPPED, tmp_path / "testbed.toml")
    (tmp_path / "crest_drive.eds").write_text("[FileInfo]\n")
    return tmp_path


@pytest.fixture
def data(config_dir: Path) -> dict:
    return tomllib.loads((config_dir / "testbed.toml").read_text())


def test_shipped_config_loads_with_derived_scaling():
    config = load_testbed_config(SHIPPED)
    assert [axis.name for axis in config.tendon_axes] == ["tendon1", "tendon2", "tendon3", "tendon4"]
    assert config.insertion_axis.node_id == 5
    assert config.bus.interface == "virtual"
    tendon = config.axis("tendon1")
    # 4096 counts/rev * 10 : 1 gear over a 5 mm drum: 4096 * 10 / (2 pi 5) counts per mm of tendon.
    assert tendon.counts_per_mm == pytest.approx(4096 * 10 / (2 * math.pi * 5.0))
    assert tendon.counts_to_mm(tendon.mm_to_counts(12.0)) == pytest.approx(12.0, abs=1 / tendon.counts_per_mm)
    # 1000 per mille of the 100 mN*m rated torque, times 10 at the drum, over 5 mm: 200 N.
    assert tendon.tension_n_from_torque_permille(1000) == pytest.approx(200.0)
    assert config.insertion_axis.home_position_mm == 20.0
    assert tendon.home_position_mm == 0.0
    assert config.axis("tendon3").eds_path == (SHIPPED.parent / "crest_drive.eds").resolve()


def test_per_axis_override_beats_kind_default(config_dir: Path, data: dict):
    data["axes"][2]["max_velocity_mm_s"] = 5.0
    config = parse_testbed_config(data, config_dir / "testbed.toml")
    assert config.axis("tendon3").max_velocity_mm_s == 5.0
    assert config.axis("tendon1").max_velocity_mm_s == 20.0
    assert config.insertion_axis.max_velocity_mm_s == 10.0


@pytest.mark.parametrize("interface", ["socketcan", "pcan", "kvaser", "ixxat", "vector", "virtual", "slcan"])
def test_any_python_can_interface_name_is_accepted(config_dir: Path, data: dict, interface: str):
    data["bus"]["interface"] = interface
    assert parse_testbed_config(data, config_dir / "testbed.toml").bus.interface == interface


def _set(path: tuple, value):
    def mutate(data: dict) -> None:
        target = data
        for key in path[:-1]:
            target = target[key]
        target[path[-1]] = value
    return mutate


def _delete(path: tuple):
    def mutate(data: dict) -> None:
        target = data
        for key in path[:-1]:
            target = target[key]
        del target[path[-1]]
    return mutate


BAD_FIELDS = [
    (_set(("axes", 2, "max_velocity_mm_s"), -1.0), "axes[2].max_velocity_mm_s", "> 0"),
    (_set(("axes", 2, "max_velocity_mm_s"), math.nan), "axes[2].max_velocity_mm_s", "finite"),
    (_set(("axis_defaults", "tendon", "gear_ratio"), "ten"), "axis_defaults.tendon.gear_ratio", "finite number"),
    (_set(("axis_defaults", "tendon", "max_tension_n"), math.inf), "axis_defaults.tendon.max_tension_n", "finite"),
    (_set(("axes", 1, "node_id"), 1), "axes[1].node_id", "unique"),
    (_set(("axes", 0, "node_id"), 128), "axes[0].node_id", "1..127"),
    (_set(("axes", 0, "node_id"), 127), "axes[0].node_id", "master.node_id"),
    (_set(("axes", 0, "node_id"), True), "axes[0].node_id", "integer"),
    (_set(("axes", 3, "name"), "tendon1"), "axes[3].name", "unique"),
    (_set(("axes", 3, "name"), "tendon5"), "axes[3].name", "tendon1"),
    (_set(("axes", 4, "kind"), "tendon"), "axes[4].kind", "'insertion'"),
    (_set(("axes", 4, "kind"), "rotation"), "axes[4].kind", "tendon, insertion"),
    (lambda data: data["axes"].pop(3), "axes", "missing tendon4"),
    (_set(("axes",), {"name": "tendon1"}), "axes", "array"),
    (_set(("axes", 1, "soft_limits_mm"), [5.0, -5.0]), "axes[1].soft_limits_mm", "min < max"),
    (_set(("axes", 1, "soft_limits_mm"), [5.0]), "axes[1].soft_limits_mm", "[min_mm, max_mm]"),
    (_set(("axis_defaults", "tendon", "soft_limits_mm"), [math.nan, 1.0]),
     "axis_defaults.tendon.soft_limits_mm[0]", "finite"),
    (_set(("axis_defaults", "tendon", "soft_limits_mm"), [-1e7, 12.0]),
     "axis_defaults.tendon.soft_limits_mm", "32-bit"),
    (_set(("axis_defaults", "insertion", "home_position_mm"), 10.0),
     "axis_defaults.insertion.home_position_mm", "inside soft_limits_mm"),
    (_set(("axis_defaults", "tendon", "tpdo1"), [[0x6041, 0, 16], [0x6064, 0, 32], [0x6077, 0, 16], [0x606C, 0, 32]]),
     "axis_defaults.tendon.tpdo1", "64 bits"),
    (_set(("axes", 0, "rpdo1"), [[0x607A, 0, 32]]), "axes[0].rpdo1", "0x6040"),
    (_set(("axes", 0, "tpdo1"), [[0x6041, 0, 16], [0x6064, 0, 32]]), "axes[0].tpdo1", "0x6077"),
    (_set(("axes", 0, "tpdo1"), [[0x6041, 0, 16], [0x6064, 0, 32], [0x6077, 0]]), "axes[0].tpdo1[2]", "[index, subindex, bits]"),
    (_set(("axes", 0, "tpdo1"), [[0x6041, 0, 16], [0x6064, 256, 32], [0x6077, 0, 16]]), "axes[0].tpdo1[1][1]", "0..255"),
    (_set(("axis_defaults", "tendon", "eds"), "missing.eds"), "axis_defaults.tendon.eds", "does not exist"),
    (_set(("axes", 4, "eds"), 3), "axes[4].eds", "EDS file name"),
    (_set(("axes", 0, "homing_method"), 200), "axes[0].homing_method", "-128..127"),
    (_set(("axes", 0, "encoder_counts_per_rev"), 0), "axes[0].encoder_counts_per_rev", "integer"),
    (_set(("axes", 0, "max_velocity"), 5.0), "axes[0].max_velocity", "unknown key"),
    (_delete(("axis_defaults", "insertion", "max_velocity_mm_s")), "axes[4].max_velocity_mm_s",
     "axis_defaults.insertion"),
    (_set(("bus", "interface"), 5), "bus.interface", "non-empty string"),
    (_set(("bus", "channel"), ""), "bus.channel", "python-can channel"),
    (_set(("bus", "bitrate"), 2_000_000), "bus.bitrate", "1..1000000"),
    (_delete(("bus", "bitrate")), "bus.bitrate", "required"),
    (_set(("sync", "period_s"), 0.0), "sync.period_s", "> 0"),
    (_set(("sync", "period_s"), 1e-7), "sync.period_s", "whole number of us"),
    (_set(("sync", "realtime_priority"), 100), "sync.realtime_priority", "0..99"),
    (_set(("sync", "realtime_priority"), 20.5), "sync.realtime_priority", "integer"),
    (_set(("sync", "realtime_priority"), "high"), "sync.realtime_priority", "integer"),
    (_delete(("sync",)), "sync", "required"),
    (_set(("sync",), 0.01), "sync", "expected a table"),
    (_set(("master", "heartbeat_timeout_s"), 0.05), "master.heartbeat_timeout_s", "heartbeat periods"),
    (_set(("master", "heartbeat_period_s"), 0.0505), "master.heartbeat_period_s", "whole number of ms"),
    (_set(("master", "sdo_timeout_s"), -0.5), "master.sdo_timeout_s", "> 0"),
    (_set(("tracker", "tool_port"), "XYZ"), "tracker.tool_port", "two hex digits"),
    (_set(("tracker", "loss_timeout_s"), "fast"), "tracker.loss_timeout_s", "finite number"),
    (_set(("coordination", "pretension_mm"), -0.1), "coordination.pretension_mm", ">= 0"),
    (_set(("extra_section",), {}), "extra_section", "unknown key"),
]


@pytest.mark.parametrize(("mutate", "field", "expected"), BAD_FIELDS, ids=[case[1] for case in BAD_FIELDS])
def test_bad_field_is_one_error_naming_file_and_field(config_dir: Path, data: dict, mutate, field, expected):
    mutate(data)
    config_path = config_dir / "testbed.toml"
    with pytest.raises(ConfigError) as raised:
        parse_testbed_config(data, config_path)
    error = raised.value
    assert error.field == field
    assert expected in error.expected
    assert str(error).startswith(f"{config_path}: {field}: ")


def test_unchanged_copy_is_accepted(config_dir: Path, data: dict):
    """The mutations above start from a valid configuration."""
    pristine = copy.deepcopy(data)
    parse_testbed_config(data, config_dir / "testbed.toml")
    assert data == pristine


def test_invalid_toml_names_file_and_line(config_dir: Path):
    path = config_dir / "testbed.toml"
    text = path.read_text().replace("period_s = 0.01", "period_s = = 0.01")
    path.write_text(text)
    with pytest.raises(ConfigError, match=r"testbed\.toml: invalid TOML: .*line \d+"):
        load_testbed_config(path)


def test_missing_file_and_non_utf8_are_config_errors(tmp_path: Path):
    with pytest.raises(ConfigError, match="cannot read the file"):
        load_testbed_config(tmp_path / "absent.toml")
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b"[bus]\ninterface = \"\xff\"\n")
    with pytest.raises(ConfigError, match="not UTF-8"):
        load_testbed_config(binary)


def test_eds_is_resolved_relative_to_the_config_file(tmp_path: Path, data: dict):
    elsewhere = tmp_path / "elsewhere"
    (elsewhere / "drives").mkdir(parents=True)
    (elsewhere / "drives" / "other.eds").write_text("[FileInfo]\n")
    (elsewhere / "crest_drive.eds").write_text("[FileInfo]\n")
    data["axis_defaults"]["insertion"]["eds"] = "drives/other.eds"
    config = parse_testbed_config(data, elsewhere / "testbed.toml")
    assert config.insertion_axis.eds_path == (elsewhere / "drives" / "other.eds").resolve()
    (elsewhere / "drives" / "other.eds").unlink()
    with pytest.raises(ConfigError, match=r"axis_defaults\.insertion\.eds: EDS file .*elsewhere/drives/other\.eds "
                                          r"does not exist.*eds = \"/path/to/other\.eds\""):
        parse_testbed_config(data, elsewhere / "testbed.toml")


def test_a_copied_config_without_its_eds_finds_the_packaged_eds(tmp_path: Path):
    """The README's recipe: copy testbed.toml elsewhere and edit it; the shipped EDS is not copied."""
    shutil.copy(SHIPPED, tmp_path / "testbed.toml")
    config = load_testbed_config(tmp_path / "testbed.toml")
    assert config.axis("tendon1").eds_path == (SHIPPED.parent / "crest_drive.eds").resolve()
    (tmp_path / "crest_drive.eds").write_text("[FileInfo]\n")          # an EDS beside the copy wins
    assert load_testbed_config(tmp_path / "testbed.toml").axis("tendon1").eds_path == tmp_path / "crest_drive.eds"
