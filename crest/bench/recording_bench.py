"""Benchmark of recording in simulated time: `crest excite --short --fast`'s path, which every blind-benchmark
case runs two or three times (training and held-out logs, and on the rod family a held-out log of the
plant without its effect), with the virtual testbed in this process as the blind benchmark has it.

What it measures is the whole stack per SYNC cycle: the master's cycle, the simulated CiA 402 drives on
python-can's virtual bus, the tracker on its pseudo-terminal, the recorder, the cc controller and the
plant's step. Its rate, SYNC cycles per second of this process's CPU time, is what bounds a blind
case's recording on one core.
"""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

from crest.backend import plant_description_family
from crest.bench.plant_bench import ROD_PLANT_TOML
from crest.config import load_testbed_config
from crest.experiment.excitation_run import plan_excitation, record_excitation
from crest.session import SessionOptions, open_session
from model import CatheterParams


def excitation_recording(plant_config: Path | None) -> dict:
    """Boot, home and record the short excitation (conditioning, training and held-out logs) in simulated
    time on the plant that `plant_config` describes (None: configs/virtual_plant.toml). cycles: SYNC
    cycles of the runs (conditioning and logs; boot, homing and the moves to each start not counted);
    wall_s and cpu_s: the whole command, boot included."""
    config, prior = load_testbed_config(), CatheterParams.from_toml()
    plan = plan_excitation(config, prior, short=True)
    cycles = 0

    def count(name: str, done: int, total: int) -> None:
        nonlocal cycles
        cycles += 1

    with tempfile.TemporaryDirectory() as folder:
        start, start_cpu = time.perf_counter(), time.process_time()
        options = SessionOptions(config=config, plant_config=plant_config, realtime=False, in_process=True)
        with open_session(options) as session:
            record_excitation(session, plan, Path(folder), prior, on_cycle=count)
        wall_s, cpu_s = time.perf_counter() - start, time.process_time() - start_cpu
    simulated_s = cycles * config.sync.period_s
    return {"family": plant_description_family(plant_config), "sync_cycles": cycles, "simulated_s": simulated_s,
            "wall_s": wall_s, "cpu_s": cpu_s, "cycles_per_cpu_s": cycles / cpu_s,
            "simulated_time_factor": simulated_s / wall_s}


def recording() -> dict:
    """The short excitation recorded on the default Dahl plant and on the rod plant (configs/rod_plant.toml,
    the grid the blind benchmark's rod cases use)."""
    return {"dahl": excitation_recording(None), "rod": excitation_recording(ROD_PLANT_TOML)}
