"""The layout follows the data flow: the core never names the simulator, and the simulator's packages
import only packages before them (world -> perception -> mapping -> navigation -> experiments
-> interfaces)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FLOW = ("world", "perception", "mapping", "navigation", "experiments", "interfaces")


def imported_modules(path: Path, package: str) -> set[str]:
    """Absolute names of every module ``path`` imports (relative imports resolved against ``package``)."""
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[: len(parts) - node.level + 1] + ([base] if base else []))
            names.add(base)
            names.update(f"{base}.{alias.name}" for alias in node.names)
    return names


def package_of(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts if parts[-1] == "__init__" else parts[:-1]).removesuffix(".__init__")


def modules(top: str) -> list[Path]:
    return sorted((ROOT / top).rglob("*.py"))


@pytest.mark.parametrize("path", modules("abstract_map"), ids=lambda p: p.name)
def test_core_never_names_the_simulator(path):
    imports = imported_modules(path, package_of(path))
    assert not {m for m in imports if m == "sim" or m.startswith("sim.")}
    assert "sim." not in path.read_text(), "the core must not name the simulator, not even in a string"


def test_every_simulator_module_lives_in_a_flow_package():
    loose = [p.name for p in (ROOT / "sim").glob("*.py") if p.name != "__init__.py"]
    assert loose == []
    packages = sorted(p.name for p in (ROOT / "sim").iterdir() if (p / "__init__.py").is_file())
    assert packages == sorted(FLOW)


@pytest.mark.parametrize("path", modules("sim"), ids=lambda p: str(p.relative_to(ROOT)))
def test_simulator_imports_run_down_the_flow(path):
    package = package_of(path)
    parts = package.split(".")
    if len(parts) < 2:
        return  # sim/__init__.py
    own = FLOW.index(parts[1])
    for name in imported_modules(path, package):
        bits = name.split(".")
        if bits[0] == "sim" and len(bits) > 1 and bits[1] in FLOW:
            assert FLOW.index(bits[1]) <= own, f"{path.relative_to(ROOT)} imports {name}, later in the flow"


def test_the_layout_test_sees_a_violation(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text("from sim.experiments.trial import run_trial\nfrom .planner import plan\n")
    assert {"sim.experiments.trial", "sim.navigation.planner"} <= imported_modules(bad, "sim.navigation")
