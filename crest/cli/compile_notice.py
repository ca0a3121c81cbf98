"""One line on stderr when the model kernel compiles, so a first run's silent minute is explained."""
from __future__ import annotations

import sys

from model.jit import on_first_compile

COMPILE_NOTICE = ("crest: compiling the model kernel (first run only, a minute or two; "
                  "later runs load it from numba's cache)...")


def announce_compiles() -> None:
    """Print COMPILE_NOTICE when a model kernel starts compiling (never when the cache has it)."""
    on_first_compile(lambda: print(COMPILE_NOTICE, file=sys.stderr, flush=True))
