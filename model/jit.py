"""The one compilation setting of the model's hot loop.

numba with NumPy's error model (no ZeroDivisionError checks in the inner loops), cached on disk
so later runs start at once. Every kernel is inlined into its jitted callers: the per-element
helpers are called some 100 times per step with a dozen array arguments each, and the call
overhead (argument structs and reference counts) cost a third of the step.
No fast-math: reassociated arithmetic can flip the solver's slack and clamp decisions on hard
steps, so the compiled kernel keeps IEEE semantics and gives the same numbers as the Python
code it compiles.
"""
from collections.abc import Callable

from numba import njit
from numba.core import event

_KERNELS: set = set()


def kernel(function):
    dispatcher = njit(cache=True, error_model="numpy", inline="always")(function)
    _KERNELS.add(dispatcher)
    return dispatcher


class _FirstCompile(event.Listener):
    """Calls back once, when numba starts compiling one of our kernels (it compiles only on a
    miss of its on-disk cache: the first run, or after the source changed)."""

    def __init__(self, callback: Callable[[], None]):
        self.callback = callback
        self.called = False

    def on_start(self, ev: event.Event) -> None:
        if not self.called and ev.data["dispatcher"] in _KERNELS:
            self.called = True
            self.callback()

    def on_end(self, ev: event.Event) -> None:
        pass


def on_first_compile(callback: Callable[[], None]) -> None:
    """Call `callback` once, when a model kernel starts compiling because the disk cache lacks it."""
    event.register("numba:compile", _FirstCompile(callback))
