"""One operator session: the testbed a configuration names, booted, with its tip tracker.

`open_session` is what every CLI command and experiment uses. Leaving it by any route (normal
end, Ctrl-C, an exception, a safety stop) leaves every axis stopped and the bus closed. In it a
Ctrl-C or SIGTERM is taken at the start of the next SYNC cycle (crest.driver.stop_requests).
"""
from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass
from pathlib import Path

from crest.backend import Backend, open_backend
from crest.config import TestbedConfig, load_testbed_config
from crest.driver import MonotonicClock, SteppedClock, Testbed, stop_requests
from crest.driver.realtime_scheduling import Scheduling, realtime_threads
from crest.experiment.tip_feed import TipFeed
from crest.testbed_service.cpu_split import beside
from crest.tracker import AuroraDriver

TRACKER_RATE_HZ = 40.0          # the Aurora's sample rate


@dataclass
class Session:
    config: TestbedConfig
    backend: Backend
    testbed: Testbed
    tracker: AuroraDriver | None
    realtime: bool = True
    scheduling: Scheduling = Scheduling()     # what this process's threads run under

    def start_fault_clock(self) -> None:
        """The virtual testbed's --fault times count from now: called where a command's motion
        starts (a run's trajectory, the jog loop, homing for `crest home`). The first call counts."""
        self.backend.start_fault_clock()

    def tip_feed(self) -> TipFeed:
        """Tip samples on the loop's clock (paced to the tracker rate when time is simulated)."""
        return TipFeed(self.tracker, None if self.realtime else 1.0 / TRACKER_RATE_HZ)


@dataclass(frozen=True)
class SessionOptions:
    """What to open. plant/plant_config/faults/effects/tracker_* apply to the virtual testbed only.

    realtime=False runs the virtual testbed in simulated time (deterministic tests). in_process boots
    the virtual testbed inside this process, on python-can's in-process bus, instead of in a process
    of its own (crest.backend): for callers that reach into the simulator (`backend.virtual`, tests)
    and for data generators that record many logs, where the second process costs CPU.
    on_notice(line) is told what the operator should know but that stops nothing: a real-time
    priority (the configuration's [sync] realtime_priority) that the system did not grant.
    """

    config_path: Path | None = None
    config: TestbedConfig | None = None     # an already loaded configuration (overrides config_path)
    plant: str | None = None
    plant_config: Path | None = None        # the default plant's description (default configs/virtual_plant.toml)
    faults: Sequence[str] = ()
    effects: dict | None = None
    realtime: bool = True
    in_process: bool = False
    boot: bool = True
    tracker: bool = True
    tracker_rate_hz: float = TRACKER_RATE_HZ
    tracker_noise_mm: float | None = None     # virtual tracker: overrides configs/virtual_plant.toml
    tracker_dropout: float | None = None
    on_notice: Callable[[str], None] = lambda line: None


@contextmanager
def open_session(options: SessionOptions = SessionOptions()) -> Iterator[Session]:
    config = options.config if options.config is not None else load_testbed_config(options.config_path)
    backend = open_backend(config, plant=options.plant, plant_config=options.plant_config, faults=options.faults,
                           effects=options.effects,
                           realtime=options.realtime, in_process=options.in_process,
                           tracker_noise_mm=options.tracker_noise_mm,
                           tracker_dropout=options.tracker_dropout)
    with ExitStack() as stack:
        stack.enter_context(stop_requests.at_safe_points())     # left last: after every part is closed
        stack.callback(backend.close)
        if backend.served is not None:
            stack.enter_context(beside(backend.served.cpus))
        scheduling = Scheduling()
        if options.realtime:
            scheduling = stack.enter_context(realtime_threads(config.sync.realtime_priority))
            if scheduling.refused:
                options.on_notice(f"{scheduling.refused}; the cycle runs under the normal scheduler")
        clock = MonotonicClock() if options.realtime else SteppedClock(on_advance=backend.tick)
        testbed = Testbed(backend.bus, config, clock=clock)
        tracker = None
        if options.tracker:
            # in simulated time the feed asks for each frame (one per tracker period of simulated time)
            rate_hz = options.tracker_rate_hz if options.realtime else None
            tracker = AuroraDriver(backend.tracker_port, baudrate=config.tracker.baudrate,
                                   tool_port=config.tracker.tool_port, rate_hz=rate_hz,
                                   port_alive=backend.tracker_port_alive)
            tracker.start()
            stack.callback(tracker.stop)
        with testbed:
            if options.boot:
                testbed.boot()
            else:
                testbed.connect()
            yield Session(config, backend, testbed, tracker, options.realtime, scheduling)
