"""The default configuration files, shipped with the distribution as package data.

testbed.toml (the virtual testbed), crest_drive.eds (the drives' object dictionary),
catheter.toml (the controller's catheter model) and virtual_plant.toml (the simulated catheter).
A data package with no code of ours, so every layer (model, sim_backend, crest) finds them both
in the source tree and in an installed wheel without importing another layer.
"""
from pathlib import Path

CONFIG_DIR = Path(__file__).resolve().parent
