"""The one compilation setting of the model's hot loop.

numba with NumPy's error model (no ZeroDivisionError checks in the inner loops) and the
fast-math flags that keep NaN and infinity semantics (the kernel uses dt = inf for a purely
quasi-static move and tests finiteness), cached on disk so later runs start at once.
"""
from numba import njit

FAST_MATH = {"nsz", "arcp", "contract", "reassoc", "afn"}


def kernel(function):
    return njit(cache=True, error_model="numpy", fastmath=FAST_MATH)(function)

