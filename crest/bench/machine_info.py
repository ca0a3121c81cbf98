"""What machine a benchmark ran on, recorded beside every result."""
from __future__ import annotations

import os
import platform
from datetime import datetime, timezone
from importlib import metadata


def machine_info() -> dict:
    packages = {}
    for name in ("numpy", "scipy", "numba", "python-can", "canopen", "filterpy"):
        try:
            packages[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            packages[name] = None
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next((line.split(":", 1)[1].strip() for line in f if line.startswith("model name")), cpu)
    except OSError:
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "python": platform.python_version(),
            "platform": platform.platform(), "packages": packages,
            "date_utc": datetime.now(timezone.utc).isoformat(timespec="seconds")}
