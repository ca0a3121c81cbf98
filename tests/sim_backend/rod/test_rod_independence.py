"""The rod plant shares no code with `model`: nothing it imports, directly or transitively, is `model`."""
from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[3]
OUR_PACKAGES = ("model", "control", "sim_backend", "crest")
ROD_PACKAGE = "sim_backend.plant.rod"


def _module_file(module: str) -> Path | None:
    path = REPO.joinpath(*module.split("."))
    if (path / "__init__.py").exists():
        return path / "__init__.py"
    if path.with_suffix(".py").exists():
        return path.with_suffix(".py")
    return None


def _imports(module: str, file: Path) -> set[str]:
    """Modules this file imports (absolute names), with the packages an import runs on the way."""
    package = module if file.name == "__init__.py" else module.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(file.read_text())):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[:len(parts) - node.level + 1] + ([base] if base else []))
            names = [base] + [f"{base}.{alias.name}" for alias in node.names]
        else:
            continue
        for name in names:
            parts = name.split(".")
            found.update(".".join(parts[:i]) for i in range(1, len(parts) + 1))
    return found


def _reachable_modules() -> set[str]:
    """Our modules the rod package reaches through imports, including the parent packages that
    importing it runs (sim_backend, sim_backend.plant)."""
    todo = ["sim_backend", "sim_backend.plant"]
    todo += [f"{ROD_PACKAGE}.{p.stem}" if p.stem != "__init__" else ROD_PACKAGE
             for p in (REPO / "sim_backend" / "plant" / "rod").glob("*.py")]
    seen: set[str] = set()
    while todo:
        module = todo.pop()
        if module in seen:
            continue
        seen.add(module)
        file = _module_file(module)
        if file is None:
            continue
        todo += [name for name in _imports(module, file) if name.split(".")[0] in OUR_PACKAGES]
    return seen


def test_no_module_the_rod_plant_reaches_is_model():
    reached = _reachable_modules()
    assert f"{ROD_PACKAGE}.step_solver" in reached and "sim_backend.plant.plant_runner" in reached
    forbidden = sorted(m for m in reached if m.split(".")[0] in ("model", "control", "crest"))
    assert not forbidden, f"the rod plant reaches {forbidden}"
    assert "sim_backend.plant.dahl_plant" not in reached


def test_running_the_rod_plant_in_a_fresh_process_never_imports_model():
    script = ("import sys\n"
              "from sim_backend.plant.rod import RodPlant\n"
              "RodPlant().step(0.01, [2.0, 0.0, -2.0, 0.0], 80.0)\n"
              "print(sorted(m for m in sys.modules if m.split('.')[0] in ('model', 'control', 'crest')))\n")
    result = subprocess.run([sys.executable, "-c", script], cwd=REPO, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[]"
