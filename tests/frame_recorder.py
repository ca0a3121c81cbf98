"""A third client of a CAN bus in the tests: it keeps every frame in the order the bus carried it,
with a condition to wait on (the driver's rig and the drives' bench both use it)."""
from __future__ import annotations

import threading

import can


class FrameRecorder(can.Listener):
    """Every frame on the bus, in the order they were carried; waits give up after wait_s [s]."""

    def __init__(self, wait_s: float) -> None:
        self.frames: list[can.Message] = []
        self.arrived = threading.Condition()
        self.wait_s = wait_s

    def on_message_received(self, msg: can.Message) -> None:
        with self.arrived:
            self.frames.append(msg)
            self.arrived.notify_all()

    def snapshot(self) -> list[can.Message]:
        with self.arrived:
            return list(self.frames)

    def with_id(self, cob_id: int) -> list[can.Message]:
        with self.arrived:
            return [frame for frame in self.frames if not frame.is_error_frame and frame.arbitration_id == cob_id]

    def error_frames(self) -> list[can.Message]:
        with self.arrived:
            return [frame for frame in self.frames if frame.is_error_frame]

    def wait_for(self, predicate, what: str) -> None:
        """Wait until predicate(every frame so far) holds."""
        with self.arrived:
            if not self.arrived.wait_for(lambda: predicate(self.frames), timeout=self.wait_s):
                raise AssertionError(f"timed out waiting for {what}")

    def wait_for_frame(self, matches, after: int, what: str) -> None:
        """Wait until a frame that `matches` arrives at an index >= `after` (each frame is looked at once)."""
        searched = [after]

        def arrived(frames) -> bool:
            found = any(matches(frame) for frame in frames[searched[0]:])
            searched[0] = len(frames)
            return found

        self.wait_for(arrived, what)

    def clear(self) -> None:
        with self.arrived:
            self.frames.clear()

    def stop(self) -> None:
        """Listener interface: nothing to release."""
