"""One line on stderr when the model kernel compiles, so a first run's silent minute is explained."""
from __future__ import annotations

import sys

COMPILE_NOTICE = ("crest: compiling the model kernel (first run only, a minute or two; "
                  "later runs load it from numba's cache)...")


def announce_compiles() -> None:
    """Print COMPILE_NOTICE when a model kernel starts compiling (never when the cache has it).

    Only in a command whose module loaded the model: every command that runs it does so at import.
    Importing the model for the notice alone would cost `crest estop`, which never runs it, numba's
    import (about half a second) before it can stop anything."""
    jit = sys.modules.get("model.jit")
    if jit is not None:
        jit.on_first_compile(lambda: print(COMPILE_NOTICE, file=sys.stderr, flush=True))
