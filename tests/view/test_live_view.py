"""The live view in a real browser (headless Chromium): a virtual `crest run --fast --view` as a
user starts it (simulated time: a loaded machine cannot starve the drives' heartbeats), its page, its refusal of requests without the session key, and its E-STOP button.

One run serves the three tests (booting the virtual testbed is the slow part): the refusals and
the live page are checked while it runs, and the E-STOP test ends it. Skipped with the reason
when no headless Chromium (Debian's chromium + chromium-driver) or selenium is installed.
"""
from __future__ import annotations

import json
import re
import signal
import subprocess
import threading
import urllib.error
import urllib.parse
import urllib.request

import pytest

from crest.bench.headless_browser import browser_missing, headless_chromium
from crest.exit_codes import ExitCode
from tests.cli.cli_runner import start_crest
from tests.view.page_reading import button, source_data, visible_text, wait_for

pytestmark = pytest.mark.skipif(browser_missing() is not None, reason=str(browser_missing()))

START_TIMEOUT_S = 120.0      # boot + homing of the virtual testbed on a loaded machine
PAGE_TIMEOUT_S = 60.0
EXIT_TIMEOUT_S = 60.0


class LiveRun:
    """A `crest run builtin:circle --view --record LOG` subprocess; its stdout read by a thread.

    In simulated time the run goes as fast as the host allows; it must last until the module's last
    test presses E-STOP on a loaded machine, so it is long (the E-STOP, or the fixture, ends it)."""

    def __init__(self, log_path):
        self.log_path = log_path
        self.process = start_crest("run", "builtin:circle", "--periods", "100", "--fast", "--view",
                                   "--record", str(log_path),
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.lines: list[str] = []
        self.stderr = ""
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        for line in self.process.stdout:
            self.lines.append(line)

    def url(self) -> str:
        def found():
            for line in self.lines:
                match = re.search(r"live view: (http://\S+)", line)
                if match:
                    return match.group(1)
            assert self.process.poll() is None, f"crest ended early: {self.lines}"
            return None
        return wait_for(found, START_TIMEOUT_S, "the printed live view link")

    def stop(self) -> None:
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
            try:
                self.process.wait(EXIT_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        self.stderr = self.process.stderr.read()


@pytest.fixture(scope="module")
def live_run(tmp_path_factory):
    run = LiveRun(tmp_path_factory.mktemp("live") / "circle.csv")
    try:
        yield run
    finally:
        run.stop()


@pytest.fixture(scope="module")
def browser():
    with headless_chromium() as driver:
        yield driver


@pytest.fixture(scope="module")
def live_page(live_run, browser):
    """The browser on the run's printed link (loaded once: a page load is slow on a loaded machine)."""
    browser.get(live_run.url())
    return browser


def test_requests_without_the_session_key_are_refused(live_run):
    url = live_run.url()
    parts = urllib.parse.urlsplit(url)
    assert parts.hostname == "127.0.0.1"
    session_id = urllib.parse.parse_qs(parts.query)["bokeh-session-id"][0]
    base = f"{parts.scheme}://{parts.netloc}/"
    forged = session_id[:-4] + ("AAAA" if not session_id.endswith("AAAA") else "BBBB")
    for refused in (base, base + "?bokeh-session-id=" + forged, base + "?bokeh-session-id=not-signed"):
        with pytest.raises(urllib.error.HTTPError) as refusal:
            urllib.request.urlopen(refused, timeout=30)
        assert refusal.value.code == 403, refused
    with urllib.request.urlopen(url, timeout=30) as page:           # the printed link itself is served
        assert page.status == 200
    websocket = urllib.request.Request(base + "ws", headers={"Connection": "Upgrade", "Upgrade": "websocket",
                                                             "Sec-WebSocket-Version": "13",
                                                             "Sec-WebSocket-Key": "dGhlIHNhbXBsZSBub25jZQ=="})
    with pytest.raises(urllib.error.HTTPError) as refusal:          # the E-STOP's channel needs a signed token
        urllib.request.urlopen(websocket, timeout=30)
    assert refusal.value.code in (400, 403)
    assert live_run.process.poll() is None, "the refused requests must not disturb the run"


def test_page_shows_backbone_and_tensions_updating_during_the_run(live_run, live_page):
    browser = live_page
    wait_for(lambda: "run builtin:circle, controller cc" in visible_text(browser) and "cycles (" in
             visible_text(browser), PAGE_TIMEOUT_S, "the run's progress on the page")
    first = wait_for(lambda: source_data(browser, "backbone"), PAGE_TIMEOUT_S, "the backbone's data")
    assert len(first["x"]) > 2 and max(first["z"]) > 10.0, first          # a catheter sticking out of the tube
    tensions = wait_for(lambda: (data := source_data(browser, "tensions")) and len(data["t"]) > 5 and data,
                        PAGE_TIMEOUT_S, "tension samples")
    values = [value for k in range(1, 5) for value in tensions[f"tension{k}"]]
    assert all(0.0 <= value < 40.0 for value in values)   # a tendon pulls (or is slack), below max_tension_n
    assert max(values) > 1.0                               # the pretension at least

    def moved():
        data = source_data(browser, "backbone")
        return data if data["x"][-1] != first["x"][-1] or data["y"][-1] != first["y"][-1] else None
    wait_for(moved, PAGE_TIMEOUT_S, "the backbone to move with the circle")
    later = wait_for(lambda: (data := source_data(browser, "tensions")) and data["t"][-1] > tensions["t"][-1]
                     and data, PAGE_TIMEOUT_S, "newer tension samples")
    assert later["t"][-1] > tensions["t"][-1]
    text = visible_text(browser)
    for axis in ("tendon1", "tendon2", "tendon3", "tendon4", "insertion"):
        assert axis in text
    assert "OPERATION ENABLED" in text
    assert live_run.process.poll() is None, "the run must still be going"


PROBE_JS = """
window.crestProbe = [];
const frame = Bokeh.documents[0].get_model_by_name("frame_sent");
frame.connect(frame.properties.text.change, () => window.crestProbe.push("frame " + frame.text));
function paint() { window.crestProbe.push("paint"); requestAnimationFrame(paint); }
requestAnimationFrame(paint);
"""

BLOCK_JS = """
const start = Date.now();
while (Date.now() < start + 1000 * arguments[0]) {}
window.crestProbe.push("unblocked");
return [start, Date.now()];
"""


def test_a_page_too_busy_to_draw_gets_no_backlog_of_frames(live_run, live_page):
    """A page that cannot keep up (here: its thread blocked for 3 s, 30 of the server's frame periods)
    must not find a queue of frames when it can draw again: the server sends the next frame only
    after the browser has painted the last (paint_handshake.py). Each frame carries its send time
    (Unix ms; the browser's clock is the machine's), so the frames sent during the block are counted."""
    browser = live_page
    sent_and_painted = lambda: browser.execute_script(
        "const docs = window.Bokeh ? Bokeh.documents : []; if (!docs.length) return null;"
        " return [docs[0].get_model_by_name('frame_sent').text, docs[0].get_model_by_name('frame_painted').text];")
    wait_for(lambda: (numbers := sent_and_painted()) and int(numbers[1].split()[0]) > 2, PAGE_TIMEOUT_S,
             "the browser to acknowledge painted frames")
    browser.execute_script(PROBE_JS)
    block_start_ms, block_end_ms = browser.execute_script(BLOCK_JS, 3.0)
    events = wait_for(lambda: (probe := browser.execute_script("return window.crestProbe;"))
                      and sum(e.startswith("frame") for e in probe[probe.index("unblocked"):]) >= 3 and probe,
                      PAGE_TIMEOUT_S, "three frames after the block")
    frames = [(int(e.split()[1]), float(e.split()[2])) for e in events if e.startswith("frame")]
    sent_while_blocked = [n for n, sent_ms in frames if block_start_ms < sent_ms < block_end_ms]
    assert len(sent_while_blocked) <= 1, f"frames sent to a page that could not draw: {sent_while_blocked}"
    numbers = [n for n, _ in frames]
    assert numbers == sorted(numbers) and len(set(numbers)) == len(numbers)     # every frame is new
    assert live_run.process.poll() is None, "the run must still be going"


def test_estop_button_stops_the_run_with_its_cause_in_the_log(live_run, live_page):
    browser = live_page
    estop = wait_for(lambda: button(browser, "E-STOP"), PAGE_TIMEOUT_S, "the E-STOP button")
    wait_for(lambda: "cycles (" in visible_text(browser), PAGE_TIMEOUT_S, "the run to be going")
    browser.execute_script("arguments[0].click();", estop)     # a click event, without waiting for a redraw
    assert live_run.process.wait(EXIT_TIMEOUT_S) == ExitCode.INTERRUPTED
    live_run.stop()
    assert "E-STOP button in the live view" in live_run.stderr
    summary = json.loads(live_run.log_path.with_suffix(".json").read_text())["summary"]
    assert "E-STOP button in the live view" in summary["stop_cause"]
    assert summary["exit_code"] == ExitCode.INTERRUPTED
    assert summary["samples"] > 0
