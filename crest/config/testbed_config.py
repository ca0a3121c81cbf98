"""The testbed configuration: configs/testbed.toml loaded into validated, frozen dataclasses.

The file is validated completely before anything starts. The first problem found raises one
`ConfigError` naming the file, the field path (``axes[2].max_velocity_mm_s``) and what is
expected; unknown keys are refused so that a misspelt key cannot silently fall back to a default.

Every ``[[axes]]`` entry is merged over ``[axis_defaults.<kind>]``: the entry's own keys win.
A value wrong in the defaults is reported at ``axis_defaults.<kind>.<key>``, a value wrong in an
override at ``axes[i].<key>``.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from configs import CONFIG_DIR

REALTIME_PRIORITY_MAX = 99     # SCHED_FIFO's priorities are 1..99 on Linux

TENDON_AXIS_NAMES = ("tendon1", "tendon2", "tendon3", "tendon4")
INSERTION_AXIS_NAME = "insertion"
AXIS_KINDS = ("tendon", "insertion")

_INT32_MAX = 2**31 - 1
_PDO_PAYLOAD_BITS = 64
# Objects the driver cannot run without: it commands through the RPDO and watches state,
# position and tendon tension (from torque actual) through the TPDO.
_REQUIRED_RPDO1 = {0x6040: "controlword", 0x607A: "target position"}
_REQUIRED_TPDO1 = {0x6041: "statusword", 0x6064: "position actual", 0x6077: "torque actual"}

_AXIS_KEYS = (
    "eds", "encoder_counts_per_rev", "gear_ratio", "drum_radius_mm", "soft_limits_mm",
    "homing_method", "home_position_mm", "max_velocity_mm_s", "max_acceleration_mm_s2",
    "max_tension_n", "following_error_window_mm", "rated_torque_mnm", "rpdo1", "tpdo1",
)
_AXIS_OPTIONAL_KEYS = {"home_position_mm": 0.0}


class ConfigError(ValueError):
    """A testbed configuration that cannot be used. Nothing is started when this is raised.

    Attributes: ``path`` (the file), ``field`` (e.g. ``axes[2].max_velocity_mm_s``, or ``""``
    for the file as a whole) and ``expected`` (what the field must hold).
    """

    def __init__(self, path: Path, field: str, expected: str) -> None:
        self.path = path
        self.field = field
        self.expected = expected
        where = f"{path}: {field}" if field else f"{path}"
        super().__init__(f"{where}: {expected}")


@dataclass(frozen=True)
class PdoEntry:
    """One mapped object of a PDO: CiA 301 mapping entry (index << 16 | subindex << 8 | bits)."""

    index: int
    subindex: int
    bits: int


@dataclass(frozen=True)
class BusConfig:
    """The CAN bus handed to python-can: ``can.Bus(interface=..., channel=..., bitrate=...)``."""

    interface: str
    channel: str | int
    bitrate: int


@dataclass(frozen=True)
class SyncConfig:
    """The SYNC producer (0x1005/0x1006). TPDOs answer and the control loop runs every period_s.
    realtime_priority: the SCHED_FIFO priority of the master's and the virtual testbed's threads
    while they run in real time (crest.driver.realtime_scheduling); 0, the default, keeps the
    normal scheduler."""

    period_s: float
    realtime_priority: int = 0


@dataclass(frozen=True)
class MasterConfig:
    """The host node: its id, heartbeat producer (0x1017), the drives' heartbeat and the timeouts."""

    node_id: int
    heartbeat_period_s: float
    drive_heartbeat_period_s: float
    heartbeat_timeout_s: float
    boot_timeout_s: float
    sdo_timeout_s: float


@dataclass(frozen=True)
class TrackerConfig:
    """The NDI Aurora tip tracker on a serial port ("sim" opens the simulated tracker)."""

    port: str
    baudrate: int
    tool_port: str
    loss_timeout_s: float


@dataclass(frozen=True)
class CoordinationConfig:
    """How antagonistic tendon pairs move together."""

    pretension_mm: float


@dataclass(frozen=True)
class AxisConfig:
    """One drive: scaling, limits, homing, PDO mapping. ``axis_defaults.<kind>`` merged with overrides."""

    name: str
    kind: str
    node_id: int
    eds_path: Path
    encoder_counts_per_rev: int
    gear_ratio: float
    drum_radius_mm: float
    soft_limits_mm: tuple[float, float]
    homing_method: int
    home_position_mm: float
    max_velocity_mm_s: float
    max_acceleration_mm_s2: float
    max_tension_n: float
    following_error_window_mm: float
    rated_torque_mnm: float
    rpdo1: tuple[PdoEntry, ...]
    tpdo1: tuple[PdoEntry, ...]

    @property
    def counts_per_mm(self) -> float:
        """Encoder counts per mm of tendon (or pulley-block travel).

        One motor revolution gives ``encoder_counts_per_rev`` counts and turns the drum
        ``1 / gear_ratio`` of a revolution, which winds ``2*pi*drum_radius_mm / gear_ratio`` mm:
            counts_per_mm = encoder_counts_per_rev * gear_ratio / (2*pi*drum_radius_mm)
        """
        return self.encoder_counts_per_rev * self.gear_ratio / (2.0 * math.pi * self.drum_radius_mm)

    @property
    def soft_min_mm(self) -> float:
        return self.soft_limits_mm[0]

    @property
    def soft_max_mm(self) -> float:
        return self.soft_limits_mm[1]

    def mm_to_counts(self, position_mm: float) -> int:
        """Drive position (0x607A/0x6064, counts, rounded to the nearest count) for a position in mm."""
        return round(position_mm * self.counts_per_mm)

    def counts_to_mm(self, counts: int) -> float:
        """Position in mm for a drive position in counts."""
        return counts / self.counts_per_mm

    @property
    def tension_n_per_permille(self) -> float:
        """Tendon tension in N for one per mille of torque actual (0x6077).

        Torque actual is motor torque in per mille of the rated torque (0x6076, mN*m = N*mm).
        The gearbox multiplies it by ``gear_ratio`` at the drum, and the drum turns torque into
        tendon tension over its radius:
            tension_n = permille / 1000 * rated_torque_mnm * gear_ratio / drum_radius_mm
        (friction and inertia of the drive train are neglected).
        """
        return self.rated_torque_mnm * self.gear_ratio / (1000.0 * self.drum_radius_mm)

    def tension_n_from_torque_permille(self, torque_permille: float) -> float:
        """Tendon tension in N from torque actual (0x6077, per mille of rated torque)."""
        return torque_permille * self.tension_n_per_permille


@dataclass(frozen=True)
class TestbedConfig:
    """The whole validated testbed: bus, SYNC, host node, tracker, coordination and five axes."""

    __test__ = False  # not a pytest test class despite the name

    path: Path
    bus: BusConfig
    sync: SyncConfig
    master: MasterConfig
    tracker: TrackerConfig
    coordination: CoordinationConfig
    axes: tuple[AxisConfig, ...]

    def axis(self, name: str) -> AxisConfig:
        """The axis called ``name``; KeyError names the axes that exist."""
        for axis in self.axes:
            if axis.name == name:
                return axis
        raise KeyError(f"no axis {name!r} in {self.path}; axes are {[a.name for a in self.axes]}")

    @property
    def tendon_axes(self) -> tuple[AxisConfig, ...]:
        """tendon1..tendon4 in that order (tendon k sits at (k-1)*90 deg from +x toward +y)."""
        return tuple(self.axis(name) for name in TENDON_AXIS_NAMES)

    @property
    def insertion_axis(self) -> AxisConfig:
        return self.axis(INSERTION_AXIS_NAME)

    def as_dict(self) -> dict[str, Any]:
        """A JSON-serialisable snapshot (paths as strings), e.g. for a log sidecar."""
        return _jsonable(dataclasses.asdict(self))


def _jsonable(value: Any) -> Any:
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, dict):
        return {key: _jsonable(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(item) for item in value]
    return value


def default_config_path() -> Path:
    """The packaged configs/testbed.toml (the virtual testbed), in the source tree or an installed wheel."""
    return CONFIG_DIR / "testbed.toml"


def load_testbed_config(path: Path | str | None = None) -> TestbedConfig:
    """Read and validate a testbed TOML file (default: `default_config_path()`).

    Raises ConfigError for an unreadable file, invalid TOML or any invalid field.
    """
    config_path = Path(path) if path is not None else default_config_path()
    try:
        raw = config_path.read_bytes()
    except OSError as error:
        raise ConfigError(config_path, "", f"cannot read the file ({error.strerror or error}); "
                          "pass an existing testbed TOML with --config") from error
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError as error:
        raise ConfigError(config_path, "", f"not UTF-8 text (byte {error.start}); save it as UTF-8 TOML") from error
    except tomllib.TOMLDecodeError as error:
        raise ConfigError(config_path, "", f"invalid TOML: {error}") from error
    except RecursionError as error:
        raise ConfigError(config_path, "", "invalid TOML: nested too deeply") from error
    return parse_testbed_config(data, config_path)


def parse_testbed_config(data: Mapping[str, Any], path: Path) -> TestbedConfig:
    """Validate already-parsed TOML data; ``path`` names the file and anchors relative EDS paths."""
    path = Path(path)
    root = _Table(data, path, "")
    root.only_keys(("bus", "sync", "master", "tracker", "coordination", "axis_defaults", "axes"))
    bus = _parse_bus(root.table("bus"))
    sync = _parse_sync(root.table("sync"))
    master = _parse_master(root.table("master"))
    tracker = _parse_tracker(root.table("tracker"))
    coordination = _parse_coordination(root.table("coordination"))
    axes = _parse_axes(root, path, master.node_id)
    return TestbedConfig(path=path, bus=bus, sync=sync, master=master, tracker=tracker,
                         coordination=coordination, axes=axes)


class _Table:
    """One TOML table with its field path; typed getters raise ConfigError naming the field."""

    def __init__(self, data: Any, path: Path, prefix: str) -> None:
        if not isinstance(data, Mapping):
            raise ConfigError(path, prefix, f"expected a table, got {_describe(data)}")
        self.data = data
        self.path = path
        self.prefix = prefix

    def field(self, key: str) -> str:
        return f"{self.prefix}.{key}" if self.prefix else key

    def fail(self, key: str, expected: str) -> ConfigError:
        return ConfigError(self.path, self.field(key), expected)

    def only_keys(self, allowed: tuple[str, ...]) -> None:
        for key in self.data:
            if key not in allowed:
                raise self.fail(key, f"unknown key; expected one of {', '.join(allowed)}")

    def get(self, key: str) -> Any:
        if key not in self.data:
            raise self.fail(key, "missing; this key is required")
        return self.data[key]

    def table(self, key: str) -> _Table:
        return _Table(self.get(key), self.path, self.field(key))

    def number(self, key: str, *, minimum: float | None = None, positive: bool = False,
               maximum: float | None = None) -> float:
        return _check_number(self.get(key), self.path, self.field(key),
                             minimum=minimum, positive=positive, maximum=maximum)

    def integer(self, key: str, *, minimum: int, maximum: int) -> int:
        return _check_integer(self.get(key), self.path, self.field(key), minimum, maximum)

    def string(self, key: str) -> str:
        value = self.get(key)
        if not isinstance(value, str) or not value.strip():
            raise self.fail(key, f"expected a non-empty string, got {_describe(value)}")
        return value


def _describe(value: Any) -> str:
    text = repr(value)
    return f"{type(value).__name__} {text if len(text) <= 40 else text[:37] + '...'}"


def _check_number(value: Any, path: Path, field: str, *, minimum: float | None = None,
                  positive: bool = False, maximum: float | None = None) -> float:
    bounds = []
    if positive:
        bounds.append("> 0")
    if minimum is not None:
        bounds.append(f">= {minimum:g}")
    if maximum is not None:
        bounds.append(f"<= {maximum:g}")
    expected = "expected a finite number" + (" " + " and ".join(bounds) if bounds else "")
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(path, field, f"{expected}, got {_describe(value)}")
    number = float(value)
    if (not math.isfinite(number) or (positive and number <= 0.0)
            or (minimum is not None and number < minimum) or (maximum is not None and number > maximum)):
        raise ConfigError(path, field, f"{expected}, got {value!r}")
    return number


def _check_integer(value: Any, path: Path, field: str, minimum: int, maximum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not minimum <= value <= maximum:
        raise ConfigError(path, field, f"expected an integer in {minimum}..{maximum}, got {_describe(value)}")
    return value


def _check_whole_units(table: _Table, key: str, value_s: float, unit_s: float, unit: str, maximum: int) -> None:
    """CANopen stores these times as unsigned integers of ``unit`` (0x1006 in us, 0x1016/0x1017 in ms)."""
    units = value_s / unit_s
    if abs(units - round(units)) > 1e-6 * max(1.0, units) or not 1 <= round(units) <= maximum:
        raise table.fail(key, f"expected a whole number of {unit} between 1 and {maximum} {unit} "
                              f"(CANopen stores it so), got {value_s!r} s")


def _parse_bus(table: _Table) -> BusConfig:
    table.only_keys(("interface", "channel", "bitrate"))
    channel = table.get("channel")
    if isinstance(channel, bool) or not isinstance(channel, (str, int)) or (isinstance(channel, str) and not channel):
        raise table.fail("channel", f"expected a python-can channel (non-empty string or integer), got {_describe(channel)}")
    return BusConfig(interface=table.string("interface"), channel=channel,
                     bitrate=table.integer("bitrate", minimum=1, maximum=1_000_000))


def _parse_sync(table: _Table) -> SyncConfig:
    table.only_keys(("period_s", "realtime_priority"))
    period_s = table.number("period_s", positive=True)
    _check_whole_units(table, "period_s", period_s, 1e-6, "us", 0xFFFFFFFF)
    realtime_priority = (table.integer("realtime_priority", minimum=0, maximum=REALTIME_PRIORITY_MAX)
                         if "realtime_priority" in table.data else 0)
    return SyncConfig(period_s=period_s, realtime_priority=realtime_priority)


def _parse_master(table: _Table) -> MasterConfig:
    table.only_keys(("node_id", "heartbeat_period_s", "drive_heartbeat_period_s", "heartbeat_timeout_s",
                     "boot_timeout_s", "sdo_timeout_s"))
    master = MasterConfig(
        node_id=table.integer("node_id", minimum=1, maximum=127),
        heartbeat_period_s=table.number("heartbeat_period_s", positive=True),
        drive_heartbeat_period_s=table.number("drive_heartbeat_period_s", positive=True),
        heartbeat_timeout_s=table.number("heartbeat_timeout_s", positive=True),
        boot_timeout_s=table.number("boot_timeout_s", positive=True),
        sdo_timeout_s=table.number("sdo_timeout_s", positive=True),
    )
    for key in ("heartbeat_period_s", "drive_heartbeat_period_s", "heartbeat_timeout_s"):
        _check_whole_units(table, key, getattr(master, key), 1e-3, "ms", 0xFFFF)
    slowest_producer_s = max(master.heartbeat_period_s, master.drive_heartbeat_period_s)
    if master.heartbeat_timeout_s <= slowest_producer_s:
        raise table.fail("heartbeat_timeout_s", f"expected more than the heartbeat periods ({slowest_producer_s:g} s), "
                                                f"or every heartbeat would time out; got {master.heartbeat_timeout_s:g} s")
    return master


def _parse_tracker(table: _Table) -> TrackerConfig:
    table.only_keys(("port", "baudrate", "tool_port", "loss_timeout_s"))
    tool_port = table.string("tool_port")
    if len(tool_port) != 2 or any(char not in "0123456789ABCDEFabcdef" for char in tool_port):
        raise table.fail("tool_port", f"expected an NDI port handle of two hex digits such as \"0A\", got {tool_port!r}")
    return TrackerConfig(port=table.string("port"), baudrate=table.integer("baudrate", minimum=1, maximum=10_000_000),
                         tool_port=tool_port.upper(), loss_timeout_s=table.number("loss_timeout_s", positive=True))


def _parse_coordination(table: _Table) -> CoordinationConfig:
    table.only_keys(("pretension_mm",))
    return CoordinationConfig(pretension_mm=table.number("pretension_mm", minimum=0.0))


def _parse_axes(root: _Table, path: Path, master_node_id: int) -> tuple[AxisConfig, ...]:
    defaults = root.table("axis_defaults")
    defaults.only_keys(AXIS_KINDS)
    default_tables = {kind: defaults.table(kind) for kind in AXIS_KINDS if kind in defaults.data}
    for table in default_tables.values():
        table.only_keys(_AXIS_KEYS)

    entries = root.get("axes")
    if not isinstance(entries, list):
        raise root.fail("axes", f"expected an array of [[axes]] tables, got {_describe(entries)}")
    axes = []
    for position, entry in enumerate(entries):
        table = _Table(entry, path, f"axes[{position}]")
        table.only_keys(("name", "kind", "node_id") + _AXIS_KEYS)
        kind = table.string("kind")
        if kind not in AXIS_KINDS:
            raise table.fail("kind", f"expected one of {', '.join(AXIS_KINDS)}, got {kind!r}")
        axes.append(_parse_axis(table, default_tables.get(kind)))

    _check_axis_set(root, axes, master_node_id)
    return tuple(axes)


def _parse_axis(entry: _Table, defaults: _Table | None) -> AxisConfig:
    def source(key: str) -> _Table:
        """The table the merged value of ``key`` comes from: the entry overrides the defaults."""
        if key in entry.data or defaults is None or key not in defaults.data:
            return entry
        return defaults

    def value(key: str) -> tuple[_Table, Any]:
        table = source(key)
        if key not in table.data:
            if key in _AXIS_OPTIONAL_KEYS:
                return table, _AXIS_OPTIONAL_KEYS[key]
            raise table.fail(key, f"missing; set it in this entry or in axis_defaults.{entry.data['kind']}")
        return table, table.data[key]

    def number(key: str, **bounds: Any) -> float:
        table, raw = value(key)
        return _check_number(raw, table.path, table.field(key), **bounds)

    name = entry.string("name")
    counts_table, counts_raw = value("encoder_counts_per_rev")
    homing_table, homing_raw = value("homing_method")
    axis = AxisConfig(
        name=name,
        kind=entry.string("kind"),
        node_id=entry.integer("node_id", minimum=1, maximum=127),
        eds_path=_eds_path(*value("eds"), key="eds"),
        encoder_counts_per_rev=_check_integer(counts_raw, counts_table.path, counts_table.field("encoder_counts_per_rev"),
                                              1, _INT32_MAX),
        gear_ratio=number("gear_ratio", positive=True),
        drum_radius_mm=number("drum_radius_mm", positive=True),
        soft_limits_mm=_soft_limits(*value("soft_limits_mm")),
        # CiA 402 homing methods (0x6098) are -128..127; negative values are manufacturer specific.
        homing_method=_check_integer(homing_raw, homing_table.path, homing_table.field("homing_method"), -128, 127),
        home_position_mm=number("home_position_mm"),
        max_velocity_mm_s=number("max_velocity_mm_s", positive=True),
        max_acceleration_mm_s2=number("max_acceleration_mm_s2", positive=True),
        max_tension_n=number("max_tension_n", positive=True),
        following_error_window_mm=number("following_error_window_mm", positive=True),
        rated_torque_mnm=number("rated_torque_mnm", positive=True),
        rpdo1=_pdo(*value("rpdo1"), key="rpdo1", required=_REQUIRED_RPDO1),
        tpdo1=_pdo(*value("tpdo1"), key="tpdo1", required=_REQUIRED_TPDO1),
    )

    low_mm, high_mm = axis.soft_limits_mm
    if not low_mm <= axis.home_position_mm <= high_mm:
        table, _ = value("home_position_mm")
        raise table.fail("home_position_mm", f"expected a position inside soft_limits_mm [{low_mm:g}, {high_mm:g}] "
                                             f"for axis {name!r}, got {axis.home_position_mm:g}")
    largest_mm = max(abs(low_mm), abs(high_mm))
    if largest_mm * axis.counts_per_mm > _INT32_MAX:
        table, _ = value("soft_limits_mm")
        raise table.fail("soft_limits_mm", f"expected limits that fit a 32-bit drive position: "
                                           f"{largest_mm:g} mm is {largest_mm * axis.counts_per_mm:.3g} counts "
                                           f"at {axis.counts_per_mm:.6g} counts/mm for axis {name!r}")
    return axis


def _eds_path(table: _Table, raw: Any, *, key: str) -> Path:
    """The EDS named by `raw`: absolute, or relative to the TOML's folder.

    A testbed TOML copied elsewhere without its EDS still finds the packaged EDS of the same file
    name (configs/crest_drive.eds); anything else must exist where the TOML says.
    """
    if not isinstance(raw, str) or not raw:
        raise table.fail(key, f"expected the EDS file name (relative to the config file), got {_describe(raw)}")
    eds_path = (table.path.parent / raw).resolve()
    if eds_path.is_file():
        return eds_path
    packaged = CONFIG_DIR / Path(raw).name
    if not Path(raw).is_absolute() and packaged.is_file():
        return packaged
    raise table.fail(key, f"EDS file {eds_path} does not exist; give its path relative to {table.path.name} "
                          f"or an absolute one, e.g. eds = \"/path/to/{Path(raw).name}\"")


def _soft_limits(table: _Table, raw: Any) -> tuple[float, float]:
    field = table.field("soft_limits_mm")
    if not isinstance(raw, list) or len(raw) != 2:
        raise ConfigError(table.path, field, f"expected [min_mm, max_mm], got {_describe(raw)}")
    low_mm = _check_number(raw[0], table.path, f"{field}[0]")
    high_mm = _check_number(raw[1], table.path, f"{field}[1]")
    if not low_mm < high_mm:
        raise ConfigError(table.path, field, f"expected min < max, got [{low_mm:g}, {high_mm:g}]")
    return low_mm, high_mm


def _pdo(table: _Table, raw: Any, *, key: str, required: Mapping[int, str]) -> tuple[PdoEntry, ...]:
    """PDO mapping [[index, subindex, bits], ...]: at most 64 bits of payload in one CAN frame."""
    field = table.field(key)
    if not isinstance(raw, list) or not raw:
        raise ConfigError(table.path, field, f"expected a list of [index, subindex, bits] entries, got {_describe(raw)}")
    if len(raw) > 8:
        raise ConfigError(table.path, field, f"expected at most 8 mapped objects, got {len(raw)}")
    entries = []
    for position, item in enumerate(raw):
        item_field = f"{field}[{position}]"
        if not isinstance(item, list) or len(item) != 3:
            raise ConfigError(table.path, item_field, f"expected [index, subindex, bits], got {_describe(item)}")
        entries.append(PdoEntry(
            index=_check_integer(item[0], table.path, f"{item_field}[0]", 0x1000, 0xFFFF),
            subindex=_check_integer(item[1], table.path, f"{item_field}[1]", 0, 0xFF),
            bits=_check_integer(item[2], table.path, f"{item_field}[2]", 1, _PDO_PAYLOAD_BITS),
        ))
    total_bits = sum(entry.bits for entry in entries)
    if total_bits > _PDO_PAYLOAD_BITS:
        raise ConfigError(table.path, field, f"expected at most {_PDO_PAYLOAD_BITS} bits (one CAN frame), "
                                             f"the entries add up to {total_bits}")
    mapped = {entry.index for entry in entries}
    for index, meaning in required.items():
        if index not in mapped:
            raise ConfigError(table.path, field, f"expected 0x{index:04X} ({meaning}) to be mapped; the driver needs it")
    return tuple(entries)


def _check_axis_set(root: _Table, axes: list[AxisConfig], master_node_id: int) -> None:
    names_seen: dict[str, int] = {}
    nodes_seen: dict[int, int] = {}
    for position, axis in enumerate(axes):
        table = _Table({}, root.path, f"axes[{position}]")
        if axis.name in names_seen:
            raise table.fail("name", f"expected a unique name; {axis.name!r} is also axes[{names_seen[axis.name]}]")
        if axis.node_id in nodes_seen:
            raise table.fail("node_id", f"expected a unique node id; {axis.node_id} is also axes[{nodes_seen[axis.node_id]}]")
        if axis.node_id == master_node_id:
            raise table.fail("node_id", f"expected a node id other than the host's master.node_id {master_node_id}")
        expected_kind = "insertion" if axis.name == INSERTION_AXIS_NAME else "tendon"
        if axis.name not in TENDON_AXIS_NAMES + (INSERTION_AXIS_NAME,):
            raise table.fail("name", f"expected one of {', '.join(TENDON_AXIS_NAMES + (INSERTION_AXIS_NAME,))}, "
                                     f"got {axis.name!r}")
        if axis.kind != expected_kind:
            raise table.fail("kind", f"expected {expected_kind!r} for axis {axis.name!r}, got {axis.kind!r}")
        names_seen[axis.name] = position
        nodes_seen[axis.node_id] = position
    missing = [name for name in TENDON_AXIS_NAMES + (INSERTION_AXIS_NAME,) if name not in names_seen]
    if missing:
        raise root.fail("axes", f"expected exactly four tendon axes tendon1..tendon4 and one insertion axis; "
                                f"missing {', '.join(missing)}")
