"""The virtual testbed: drives, plant and tracker coupled as on the real testbed.

An independent client (canopen) drives the simulated amplifiers; the plant follows their
actual positions and its tendon tension comes back as torque actual (0x6077).
"""
import time
import uuid

import canopen
import numpy as np
import pytest

from drive_bench import EDS_PATH, insertion_spec, tendon_spec
from sim_backend.plant import DahlPlant, PlantConfig
from sim_backend.virtual_testbed import TrackerSettings, VirtualTestbed

TENDONS = ("tendon1", "tendon2", "tendon3", "tendon4")


def specs():
    return [tendon_spec(name, node_id) for node_id, name in enumerate(TENDONS, start=1)] + [
        insertion_spec(start_position_mm=80.0)]


class SlowPlant:
    """A plant whose step costs 4 ms of compute, like a Cosserat rod."""

    def __init__(self):
        self.steps = 0

    def reset(self):
        self.steps = 0

    def step(self, dt_s, tendon_mm, insertion_mm):
        time.sleep(0.004)
        self.steps += 1
        return np.array([0.0, 0.0, float(insertion_mm)]), np.zeros(4)


@pytest.fixture
def bench(request):
    plant = getattr(request, "param", None) or DahlPlant(PlantConfig())
    channel = f"vt-{uuid.uuid4().hex}"
    testbed = VirtualTestbed(specs(), channel, plant, tracker=TrackerSettings(noise_mm=0.0),
                             plant_in_thread=isinstance(plant, SlowPlant))
    testbed.start()
    client = canopen.Network()
    client.connect(interface="virtual", channel=channel)
    nodes = {}
    for spec in specs():
        node = canopen.BaseNode402(spec.node_id, str(EDS_PATH))
        client.add_node(node)
        nodes[spec.name] = node
    yield testbed, client, nodes
    client.disconnect()
    testbed.stop()


def enable_csp(node):
    """NMT start, cyclic synchronous position, OPERATION ENABLED, by SDO."""
    node.nmt.send_command(0x01)
    node.sdo[0x6060].raw = 8
    node.sdo[0x6040].raw = 0x06
    node.sdo[0x6040].raw = 0x0F
    assert node.sdo[0x6041].raw & 0x6F == 0x27


def sync(client, nodes, count):
    for _ in range(count):
        client.sync.transmit()
        nodes["tendon1"].sdo.upload(0x1000, 0)   # round trip: the SYNC has been processed


def test_plant_follows_the_drives_and_tension_comes_back_as_torque_actual(bench):
    testbed, client, nodes = bench
    node = nodes["tendon1"]
    enable_csp(node)
    spec = tendon_spec()
    target_mm = 3.0
    for step in range(1, 151):     # a 2 mm/s ramp in CSP, one set-point per SYNC
        node.sdo[0x607A].raw = round(target_mm * step / 150 * spec.counts_per_mm)
        sync(client, nodes, 1)
    sync(client, nodes, 20)
    assert testbed.drives.drive("tendon1").position_actual_mm == pytest.approx(target_mm, abs=0.01)
    tip, tension = testbed.plant_runner.latest()
    assert tip[0] > 30.0                       # pulling tendon 1 bends toward +x
    assert tension[0] > 1.0
    per_mille = node.sdo[0x6077].raw
    expected = tension[0] * spec.drum_radius_mm / spec.gear_ratio / spec.rated_torque_mnm * 1000.0
    assert per_mille == round(expected)


@pytest.mark.parametrize("bench", [SlowPlant()], indirect=True)
def test_slow_plant_runs_in_its_own_thread_and_drives_answer_every_sync(bench):
    testbed, client, nodes = bench
    for node in nodes.values():
        node.nmt.send_command(0x01)
    received = []
    client.subscribe(0x181, lambda *args: received.append(args))
    sync(client, nodes, 50)
    assert len(received) == 50                                # every SYNC answered
    assert 0.0 < testbed.plant_rate_hz <= 1.0 / 0.004 + 1.0   # the plant's own pace is reported


def test_scheduled_tracker_fault_fires_at_its_time():
    from sim_backend.faults import parse_fault
    channel = f"vt-{uuid.uuid4().hex}"
    testbed = VirtualTestbed(specs(), channel, DahlPlant(PlantConfig()),
                             faults=[parse_fault("tracker:missing_tool@1.0")])
    testbed.start()
    try:
        testbed.tick(0.9)
        assert not testbed.tracker.faults
        testbed.tick(1.0)
        assert "missing_tool" in {f.value for f in testbed.tracker.faults}
    finally:
        testbed.stop()


def test_tracker_reports_the_plant_tip(bench):
    from crest.tracker import AuroraDriver
    testbed, client, nodes = bench
    with AuroraDriver(testbed.tracker_port) as driver:
        sample = driver.wait_next(timeout_s=2.0)
        assert sample.tip_mm is not None
        assert np.allclose(sample.tip_mm, testbed.true_tip_mm(), atol=0.01)
