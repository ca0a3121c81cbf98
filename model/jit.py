"""The one compilation setting of the model's hot loop.

numba with NumPy's error model (no ZeroDivisionError checks in the inner loops), cached on disk
so later runs start at once. No fast-math: reassociated arithmetic can flip the solver's
slack and clamp decisions on hard steps, so the compiled kernel keeps IEEE semantics and gives
the same numbers as the Python code it compiles.
"""
from numba import njit


def kernel(function):
    return njit(cache=True, error_model="numpy")(function)

