"""The validated testbed configuration (configs/testbed.toml)."""

from crest.config.testbed_config import (
    AxisConfig,
    BusConfig,
    ConfigError,
    CoordinationConfig,
    MasterConfig,
    PdoEntry,
    SyncConfig,
    TestbedConfig,
    TrackerConfig,
    default_config_path,
    load_testbed_config,
    parse_testbed_config,
)

__all__ = [
    "AxisConfig",
    "BusConfig",
    "ConfigError",
    "CoordinationConfig",
    "MasterConfig",
    "PdoEntry",
    "SyncConfig",
    "TestbedConfig",
    "TrackerConfig",
    "default_config_path",
    "load_testbed_config",
    "parse_testbed_config",
]
