"""The stand-in for the live view when --view is not given: the same calls, nothing shown.

Its own module, so that a command without --view never imports the view's server (bokeh, tornado).
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np

from crest.session import Session


class NoView:
    """Stands in for the live view when --view is not given: the same calls, nothing shown."""

    def attach(self, session: Session) -> None:
        """Nothing to follow."""

    def follow(self, status: str, reference_mm: np.ndarray | None = None, total_cycles: int | None = None,
               then: Callable[[int], None] | None = None) -> Callable[[int], None] | None:
        return then
