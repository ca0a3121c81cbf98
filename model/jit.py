"""The one compilation setting of the model's hot loop.

numba with NumPy's error model (no ZeroDivisionError checks in the inner loops), cached on disk
so later runs start at once. Every kernel is inlined into its jitted callers: the per-element
helpers are called some 100 times per step with a dozen array arguments each, and the call
overhead (argument structs and reference counts) cost a third of the step.
No fast-math: reassociated arithmetic can flip the solver's slack and clamp decisions on hard
steps, so the compiled kernel keeps IEEE semantics and gives the same numbers as the Python
code it compiles.
"""
from numba import njit


def kernel(function):
    return njit(cache=True, error_model="numpy", inline="always")(function)
