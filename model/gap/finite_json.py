"""Strict JSON: a result tree holds only finite numbers; a non-finite one becomes null with a reason.

json.dumps writes inf and nan as `Infinity` and `NaN`, which are not JSON; `finite_tree` replaces
every non-finite float in nested dicts and lists by None and lists where it did, so a reader sees
which value is missing and why, and `json.dumps(..., allow_nan=False)` cannot fail.
"""
from __future__ import annotations

import math
from typing import Any

NON_FINITE_REASON = "not a finite number (a model prediction that diverged or was given up): written as null"


def finite_tree(tree: Any, path: str = "") -> tuple[Any, list[dict]]:
    """(the tree with non-finite floats as None, [{"path", "reason"}] of each one replaced)."""
    if isinstance(tree, float) and not math.isfinite(tree):
        return None, [{"path": path or "/", "reason": NON_FINITE_REASON}]
    if isinstance(tree, dict):
        out, nulls = {}, []
        for key, value in tree.items():
            out[key], found = finite_tree(value, f"{path}/{key}")
            nulls += found
        return out, nulls
    if isinstance(tree, (list, tuple)):
        out, nulls = [], []
        for index, value in enumerate(tree):
            item, found = finite_tree(value, f"{path}/{index}")
            out.append(item)
            nulls += found
        return out, nulls
    return tree, []
