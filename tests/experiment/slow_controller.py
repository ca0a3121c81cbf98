"""A `cc` controller that takes `pause_s` of wall time over every `every`-th command: a command
process that falls behind. Importable by the command worker (python -m, run from the repository)."""
import time

from control import ConstantCurvatureController


class SlowConstantCurvature(ConstantCurvatureController):
    every = 20
    pause_s = 0.2

    def command(self, setpoint, tip=None, drive_tension_n=None):
        self.calls = getattr(self, "calls", 0) + 1
        if self.calls % self.every == 0:
            time.sleep(self.pause_s)
        return super().command(setpoint, tip, drive_tension_n)
