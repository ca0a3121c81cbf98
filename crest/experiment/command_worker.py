"""The worker of crest.experiment.command_process: ``python -m crest.experiment.command_worker``.

stdin: one pickled (controller, insertion_mm, batch), then pickled lists of set-points.
stdout: pickled lists of what the controller's `command` returned for each set-point, in order, or
the exception it raised in that place (after which the worker computes nothing more).
A thread reads stdin into a queue, so the master's writes never wait on a computation. The worker
runs on the master's CPUs (those a served testbed leaves it: beside the testbed's real-time
threads, which wake for every frame, it fell behind at 500 Hz), resets the controller to
insertion_mm and exits when stdin closes.
"""
from __future__ import annotations

import pickle
import queue
import sys
import threading


def main() -> None:
    commands_out = sys.stdout.buffer
    sys.stdout = sys.stderr     # a stray print must not corrupt the command stream
    setpoints_in = sys.stdin.buffer
    controller, insertion_mm, batch = pickle.load(setpoints_in)
    received: queue.Queue[list | None] = queue.Queue()
    threading.Thread(target=_read, args=(setpoints_in, received), daemon=True).start()
    controller.reset(insertion_mm=insertion_mm)
    failed = False
    while (setpoints := received.get()) is not None:
        done: list = []
        for setpoint in [] if failed else setpoints:
            try:
                done.append(controller.command(setpoint))
            except Exception as error:   # raised by the master at this set-point
                done.append(error)
                failed = True
                break
            if len(done) == batch:
                _write(commands_out, done)
                done = []
        if done:
            _write(commands_out, done)


def _read(stream, received: queue.Queue) -> None:
    try:
        while True:
            received.put(pickle.load(stream))
    except (EOFError, OSError, pickle.UnpicklingError):
        received.put(None)


def _write(stream, batch: list) -> None:
    try:
        pickle.dump(batch, stream, protocol=pickle.HIGHEST_PROTOCOL)
        stream.flush()
    except BrokenPipeError:
        sys.exit(0)     # the master is gone


if __name__ == "__main__":
    main()
