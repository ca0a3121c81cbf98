"""The Aurora driver against the simulated tracker on a pseudo-terminal: set-up, streaming, faults, recovery."""

import threading

import numpy as np
import pytest
import serial

from crest.tracker import AuroraDriver, TrackerLinkError, TrackerState
from sim_backend.tracker import SimTracker

WAIT_S = 5.0  # upper bound for any condition below; the conditions themselves end the waits
# Reply and set-up timeouts are wall time and the simulated tracker answers from a thread of this
# process: they are kept well above a loaded machine's scheduling delays. Backoffs are short, so
# that the recovery tests end soon.
FAST = dict(rate_hz=200.0, reply_timeout_s=0.5, setup_timeout_s=1.0, backoff_s=0.02, max_backoff_s=0.1)


class Tip:
    """A thread-safe tip the test can move, standing in for the plant."""

    def __init__(self, tip_mm):
        self._lock = threading.Lock()
        self.set(tip_mm)

    def set(self, tip_mm):
        with self._lock:
            self._tip_mm = None if tip_mm is None else np.array(tip_mm, dtype=float)

    def __call__(self):
        with self._lock:
            return self._tip_mm


@pytest.fixture
def tip():
    return Tip([12.34, -5.67, 80.01])


@pytest.fixture
def sim(tip):
    tracker = SimTracker(tip, seed=5).start()
    yield tracker
    tracker.stop()


@pytest.fixture
def driver(sim):
    states = []
    tracker = AuroraDriver(sim.port_name, on_state=lambda state, reason: states.append((state, reason)),
                           **FAST).start()
    tracker.states_seen = states
    yield tracker
    tracker.stop()


def next_samples(driver, count):
    return [driver.wait_next(WAIT_S) for _ in range(count)]


def first_reason(driver, state):
    return next(reason for seen, reason in driver.states_seen if seen is state)


def test_set_up_follows_the_ndi_sequence(sim, driver):
    assert [c.name + ":" + c.args for c in sim.command_log][:8] == [
        "INIT:", "COMM:50000", "PHSR:02", "PINIT:0A", "PHSR:03", "PENA:0AD", "PHSR:04", "TSTART:"]
    assert driver.state is TrackerState.TRACKING
    assert sim.tracking


def test_samples_carry_the_injected_tip_timestamps_and_frames(tip, driver):
    samples = next_samples(driver, 5)
    for sample in samples:
        assert np.allclose(sample.tip_mm, [12.34, -5.67, 80.01], atol=1e-9)  # 0.01 mm fixed point, exact here
        assert sample.status == 0x31  # occupied, initialized, enabled
    assert all(b.t_s > a.t_s for a, b in zip(samples, samples[1:]))
    assert all(b.frame > a.frame for a, b in zip(samples, samples[1:]))
    tip.set([-30.0, 4.5, 60.25])
    driver.wait_next(WAIT_S)  # may have been requested before the move
    assert np.allclose(driver.wait_next(WAIT_S).tip_mm, [-30.0, 4.5, 60.25], atol=1e-9)


def test_noisy_samples_scatter_around_the_tip_by_noise_mm(tip):
    with SimTracker(tip, noise_mm=0.3, seed=11) as sim, \
            AuroraDriver(sim.port_name, **{**FAST, "rate_hz": 1000.0}) as driver:
        tips = np.array([s.tip_mm for s in next_samples(driver, 200)])
    assert np.allclose(tips.mean(axis=0), tip(), atol=4 * 0.3 / np.sqrt(200))
    assert np.allclose(tips.std(axis=0), 0.3, rtol=0.25)


def test_missing_tool_gives_none_samples_and_the_age_keeps_growing(sim, driver):
    sim.inject("missing_tool")
    previous = driver.wait_next(WAIT_S)  # the last sample that may have been requested before the fault
    missing = driver.wait_next(WAIT_S)
    assert missing.tip_mm is None
    assert missing.frame > previous.frame
    assert driver.latest() is not None and driver.age_s() >= missing.t_s - previous.t_s > 0.0
    assert driver.stats().missing >= 1
    sim.clear("missing_tool")
    driver.wait_next(WAIT_S)
    assert driver.wait_next(WAIT_S).tip_mm is not None


def test_corrupted_crc_rejects_samples_counts_them_and_recovers(sim, driver):
    before = driver.wait_next(WAIT_S)
    sim.inject("crc")
    assert driver.wait_state(TrackerState.RECONNECTING, WAIT_S)
    assert driver.stats().crc_errors >= driver.max_bad_replies
    assert driver.latest().frame - before.frame <= 1  # nothing with a bad CRC was published
    assert "unreadable replies in a row" in first_reason(driver, TrackerState.RECONNECTING)
    assert "CRC" in first_reason(driver, TrackerState.RECONNECTING)
    sim.clear("crc")
    assert driver.wait_state(TrackerState.TRACKING, WAIT_S)
    assert driver.wait_next(WAIT_S).tip_mm is not None
    assert driver.stats().reconnects == 1


def test_disconnect_is_detected_and_the_link_comes_back(sim, driver):
    driver.wait_next(WAIT_S)
    sim.inject("disconnect")
    assert driver.wait_state(TrackerState.RECONNECTING, WAIT_S)
    assert "no reply to TX:0001" in first_reason(driver, TrackerState.RECONNECTING)
    assert driver.last_error  # the state's reason stays readable while the link is down
    assert driver.stats().timeouts >= 1
    sim.clear("disconnect")
    assert driver.wait_state(TrackerState.TRACKING, WAIT_S)
    assert driver.wait_next(WAIT_S).tip_mm is not None
    assert [state for state, _ in driver.states_seen[:4]] == [
        TrackerState.CONNECTING, TrackerState.TRACKING, TrackerState.RECONNECTING, TrackerState.TRACKING]


def test_a_tracker_that_vanishes_between_polls_is_a_lost_link_not_a_crash(tip, monkeypatch):
    """The served testbed killed with -9 takes the tracker's pseudo-terminal with it, most often while
    the driver waits for its next poll: the next exchange fails on the dead line (EIO), which is a lost
    link to reconnect, never an exception that kills the polling thread."""
    crashed = []
    monkeypatch.setattr(threading, "excepthook", crashed.append)
    sim = SimTracker(tip, seed=5).start()
    states = []
    tracker = AuroraDriver(sim.port_name, on_state=lambda state, reason: states.append((state, reason)),
                           **{**FAST, "rate_hz": 5.0}).start()
    tracker.states_seen = states
    try:
        tracker.wait_next(WAIT_S)
        sim.stop()
        assert tracker.wait_state(TrackerState.RECONNECTING, WAIT_S)
        reason = first_reason(tracker, TrackerState.RECONNECTING)
        assert "TX:0001" in reason and "Input/output error" in reason, reason
        assert tracker.stats().timeouts == 0     # a line that is gone is a serial error, not a reply that was late
    finally:
        tracker.stop()
    assert crashed == [] and tracker.state is TrackerState.STOPPED


def test_a_port_gone_for_good_is_not_opened_again(tip, monkeypatch):
    """A served testbed killed with -9 takes its pseudo-terminal with it, and the kernel may give the
    terminal's number to the next testbed that starts. Told that the port is gone for good, the driver
    stops after the lost link instead of opening that number again, where another testbed's tracker
    would answer two clients on one line."""
    sim = SimTracker(tip, seed=5).start()
    alive = threading.Event()
    alive.set()
    states = []
    tracker = AuroraDriver(sim.port_name, port_alive=alive.is_set,
                           on_state=lambda state, reason: states.append((state, reason)),
                           **{**FAST, "rate_hz": 5.0}).start()
    tracker.states_seen = states
    opened = []
    monkeypatch.setattr(serial, "Serial", lambda *args, **kwargs: opened.append(args))
    try:
        tracker.wait_next(WAIT_S)
        alive.clear()
        sim.stop()
        assert tracker.wait_state(TrackerState.STOPPED, WAIT_S)
        assert "gone for good" in first_reason(tracker, TrackerState.STOPPED)
        assert [state for state, _ in states] == [TrackerState.CONNECTING, TrackerState.TRACKING,
                                                  TrackerState.RECONNECTING, TrackerState.STOPPED]
        assert opened == []
        assert "gone for good" in tracker.last_error
    finally:
        tracker.stop()
    assert tracker.state is TrackerState.STOPPED


def test_stop_sends_tstop_and_closes(sim, driver):
    driver.wait_next(WAIT_S)
    driver.stop()
    assert sim.command_log[-1].name == "TSTOP"
    assert not sim.tracking
    assert driver.state is TrackerState.STOPPED


def test_power_up_rate_needs_no_comm(tip):
    with SimTracker(tip) as sim, AuroraDriver(sim.port_name, baudrate=9600, **FAST) as driver:
        driver.wait_next(WAIT_S)
        assert "COMM" not in [c.name for c in sim.command_log]


def test_tool_on_another_port_fails_set_up_with_a_clear_message(tip):
    with SimTracker(tip, tool_handle=0x0B) as sim:
        driver = AuroraDriver(sim.port_name, tool_port="0A", **FAST)
        with pytest.raises(TrackerLinkError, match="port handle 0A is not enabled .*enabled: 0B.*tool_port"):
            driver.start()
        assert driver.state is TrackerState.STOPPED


def test_absent_port_fails_set_up_naming_the_port(tmp_path):
    absent = str(tmp_path / "ttyNONE")
    with pytest.raises(TrackerLinkError, match="ttyNONE"):
        AuroraDriver(absent, **FAST).start()


def test_no_sample_yet_means_infinite_age(sim):
    driver = AuroraDriver(sim.port_name, **FAST)
    assert driver.latest() is None
    assert driver.age_s() == float("inf")


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"tool_port": "ZZ"}, "tool_port"), ({"tool_port": "A"}, "tool_port"), ({"tool_port": "00"}, "tool_port"),
    ({"baudrate": 12345}, "baudrate"), ({"rate_hz": 0.0}, "rate_hz"), ({"max_bad_replies": 0}, "max_bad_replies"),
])
def test_invalid_settings_name_the_field(kwargs, match):
    with pytest.raises(ValueError, match=match):
        AuroraDriver("/dev/null", **kwargs)


def test_on_demand_the_driver_sends_one_tx_per_request_and_its_frame_sees_the_tool_after_the_request(sim, tip):
    """rate_hz=None (the session's mode in simulated time): no polling; each fresh_sample sends one TX,
    so the frame describes the tool as it was when asked, whatever the wall time between requests."""
    driver = AuroraDriver(sim.port_name, **{**FAST, "rate_hz": None}).start()
    try:
        tx_before = sum(c.name == "TX" for c in sim.command_log)
        threading.Event().wait(0.3)                                   # nobody asks: nothing is sent
        assert sum(c.name == "TX" for c in sim.command_log) == tx_before
        frames = []
        for k in range(5):
            tip.set([float(k), 0.0, 70.0])
            sample = driver.fresh_sample(WAIT_S)
            assert np.allclose(sample.tip_mm, [float(k), 0.0, 70.0], atol=1e-9)
            frames.append(sample.frame)
        assert sum(c.name == "TX" for c in sim.command_log) == tx_before + 5
        assert frames == sorted(set(frames))
    finally:
        driver.stop()
    assert driver.state is TrackerState.STOPPED


def test_polling_a_fresh_sample_is_one_requested_after_the_call(tip, driver):
    driver.wait_next(WAIT_S)
    tip.set([-1.0, 2.0, 75.5])
    assert np.allclose(driver.fresh_sample(WAIT_S).tip_mm, [-1.0, 2.0, 75.5], atol=1e-9)
