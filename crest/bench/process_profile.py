"""Where each process of a run spends its time: each thread's CPU, and what each thread runs.

For the process `root_pid` and every process it has started by then (the served testbed, the
command process), for the same span D of py-spy's sampling:
- **CPU**: the kernel's count of each thread's time on a CPU, in user mode and in the kernel
  (utime and stime of /proc/PID/task/TID/stat), as a share of one CPU's time:
  (utime_end - utime_start) / W, the same for stime, W the wall time (time.monotonic) between the
  two reads: py-spy takes a moment to attach and to end, so W is a little longer than D; a thread
  that started during the span counts from zero;
- **what the thread runs**: py-spy (a sampling profiler that reads a Python process's stacks
  from outside it) samples every thread `rate_hz` times a second, waiting or not (``--idle
  --threads``: the thread states py-spy would use to leave out waiting threads count every
  thread as running in this container, so the CPU comes from the kernel's counts instead).
  Each sample is put in the first component (COMPONENTS, matched on the source file's full
  path) met from the innermost frame outwards: a socket write made by the WebSocket transport
  counts as the transport's, a sample with no component frame as the runtime's. A thread's
  share of component c is S_c / S over its S samples: where it is, working or waiting.

Reading the stacks stops each process for a moment at every sample, so a profiled run is slower
than one that is not.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import threading
import time
from collections import Counter
from pathlib import Path

COMPONENTS = (   # (name, path fragment); the first fragment found in a frame's file names its component
    ("controller (control/)", "/control/"),
    ("model (model/)", "/model/"),
    ("cycle, PDOs and supervision (crest/driver/)", "/crest/driver/"),
    ("run loop, log and commands (crest/experiment/, crest/log/)", "/crest/experiment/"),
    ("run loop, log and commands (crest/experiment/, crest/log/)", "/crest/log/"),
    ("tracker client (crest/tracker/)", "/crest/tracker/"),
    ("simulated drives (sim_backend/drive/)", "/sim_backend/drive"),
    ("plant (sim_backend/plant/)", "/sim_backend/plant/"),
    ("simulated tracker (sim_backend/tracker/)", "/sim_backend/tracker/"),
    ("WebSocket transport (python-can-remote)", "/can_remote/"),
    ("WebSocket transport (python-can-remote)", "/sim_backend/bus_server.py"),
    ("python-can in-process bus", "/can/interfaces/virtual.py"),
    ("python-can", "/can/"),
    ("canopen", "/canopen/"),
    ("crest, other", "/crest/"),
    ("testbed, other (sim_backend/)", "/sim_backend/"),
)
RUNTIME = "Python runtime and standard library"
_FRAME_FILE = re.compile(r"\((.*):\d+\)$")
_THREAD_FRAME = re.compile(r"^thread \((\d+)\)(?:: ([^;]*))?;?")   # no name where the threading module is not loaded
_TICK_S = 1.0 / os.sysconf("SC_CLK_TCK")


class ProfilerUnavailable(RuntimeError):
    """py-spy is not installed, or the system does not let it read another process."""


class ProcessTreeProfile:
    """`start` profiles `root_pid` and its children of that moment; `finish` waits and summarizes."""

    def __init__(self, root_pid: int, folder: Path, rate_hz: int) -> None:
        self._executable = shutil.which("py-spy")
        if self._executable is None:
            raise ProfilerUnavailable("py-spy is not installed (pip install py-spy); it is in crest's dependencies")
        self.root_pid = root_pid
        self.folder = Path(folder)
        self.rate_hz = int(rate_hz)
        self.duration_s = 0.0
        self.unavailable = ""        # why `start` profiled nothing; `finish` raises it
        self._runs: list[dict] = []

    def start(self, duration_s: float) -> None:
        """Profile the root and its children for `duration_s` (whole seconds), each thread's CPU
        read as its process's profiler starts and as it ends. It may run in a timer thread, where an
        exception would reach no one, so what stops it is kept in `unavailable` for `finish`."""
        self.duration_s = float(max(1, int(round(duration_s))))
        self.folder.mkdir(parents=True, exist_ok=True)
        if not Path(f"/proc/{self.root_pid}").exists():
            self.unavailable = f"no process {self.root_pid} to profile"
            return
        for pid in (self.root_pid, *children_of(self.root_pid)):
            try:
                command = command_of(pid)
            except OSError:     # a child that ended meanwhile
                continue
            run = {"pid": pid, "command": command, "out": self.folder / f"profile_{pid}.txt",
                   "cpu_before": thread_cpu_seconds(pid), "read_before_s": time.monotonic()}
            run["profiler"] = subprocess.Popen(
                [self._executable, "record", "--idle", "--threads", "--full-filenames", "--format", "raw",
                 "--rate", str(self.rate_hz), "--duration", str(int(self.duration_s)), "--output", str(run["out"]),
                 "--pid", str(pid)],
                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            run["watcher"] = threading.Thread(target=self._watch, args=(run,), daemon=True)
            run["watcher"].start()
            self._runs.append(run)

    @staticmethod
    def _watch(run: dict) -> None:
        """Wait for one profiler to end, then read its process's CPU at once (before it may exit)."""
        _, run["errors"] = run["profiler"].communicate()
        run["cpu_after"] = thread_cpu_seconds(run["pid"])
        run["read_after_s"] = time.monotonic()

    def finish(self, timeout_s: float) -> list[dict]:
        """Per process profiled (root first): {"pid", "command", "raw", "cpu_user", "cpu_kernel",
        "threads": [{"tid", "name", "cpu_user", "cpu_kernel", "samples", "components": {name:
        share}}, most CPU first]}; ProfilerUnavailable, in py-spy's words, where py-spy wrote no
        profile of a process or where `start` could not begin."""
        if self.unavailable:
            raise ProfilerUnavailable(self.unavailable)
        rows = []
        for run in self._runs:
            run["watcher"].join(timeout_s)
            if run["watcher"].is_alive():
                run["profiler"].kill()
                run["watcher"].join()
            if not run["out"].exists():
                last = (run["errors"] or "").strip().splitlines()
                raise ProfilerUnavailable(f"py-spy wrote no profile of pid {run['pid']} "
                                          f"(exit {run['profiler'].returncode}): {last[-1] if last else 'no message'}")
            names, counts = thread_components(run["out"])
            threads, window_s = [], run["read_after_s"] - run["read_before_s"]
            for tid, (user_after, kernel_after) in run["cpu_after"].items():
                user_before, kernel_before = run["cpu_before"].get(tid, (0.0, 0.0))
                samples = sum(counts.get(tid, Counter()).values())
                threads.append({"tid": tid, "name": names.get(tid, "(not sampled)"),
                                "cpu_user": (user_after - user_before) / window_s,
                                "cpu_kernel": (kernel_after - kernel_before) / window_s,
                                "samples": samples,
                                "components": {name: n / samples for name, n in counts[tid].most_common()}
                                if samples else {}})
            threads.sort(key=lambda t: -(t["cpu_user"] + t["cpu_kernel"]))
            rows.append({"pid": run["pid"], "command": run["command"], "raw": str(run["out"]),
                         "cpu_user": sum(t["cpu_user"] for t in threads),
                         "cpu_kernel": sum(t["cpu_kernel"] for t in threads), "threads": threads})
        return rows


def children_of(pid: int) -> list[int]:
    """The processes whose parent is `pid` now (from /proc/*/stat)."""
    children = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:          # the process ended meanwhile
            continue
        if int(fields[1]) == pid:
            children.append(int(stat.parent.name))
    return sorted(children)


def command_of(pid: int) -> str:
    """The command line of `pid` (arguments joined by spaces)."""
    return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace").strip()


def thread_cpu_seconds(pid: int) -> dict[int, tuple[float, float]]:
    """{tid: (user, kernel) CPU seconds so far} of every thread of `pid` now ({} once it is gone)."""
    seconds = {}
    for stat in Path(f"/proc/{pid}/task").glob("*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:          # the thread ended meanwhile
            continue
        seconds[int(stat.parent.name)] = (int(fields[11]) * _TICK_S, int(fields[12]) * _TICK_S)  # utime, stime
    return seconds


def component_of(frames: list[str]) -> str:
    """The component of one stack (frames root first): the first COMPONENTS match from the innermost frame."""
    for frame in reversed(frames):
        found = _FRAME_FILE.search(frame)
        path = found.group(1) if found else ""
        for name, fragment in COMPONENTS:
            if fragment in path:
                return name
    return RUNTIME


def thread_components(raw_path: Path) -> tuple[dict[int, str], dict[int, Counter]]:
    """({tid: thread name}, {tid: samples per component}) from py-spy's raw output with --threads:
    one "thread (TID): NAME;frame;frame;... count" line per distinct stack, root first (without
    ": NAME" for a thread that Python's threading module has not named)."""
    names: dict[int, str] = {}
    counts: dict[int, Counter] = {}
    for line in raw_path.read_text().splitlines():
        stack, _, count = line.rpartition(" ")
        thread = _THREAD_FRAME.match(stack)
        if thread is None or not count.isdigit():
            continue
        tid = int(thread.group(1))
        names[tid] = thread.group(2) or "(no name)"
        counts.setdefault(tid, Counter())[component_of(stack[thread.end():].split(";"))] += int(count)
    return names, counts
