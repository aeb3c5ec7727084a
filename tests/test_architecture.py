"""The package keeps its dependency direction and its modules stay small."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SOURCE = Path(__file__).resolve().parents[1] / "src" / "cyborg"
INDEPENDENT = ("bt", "bus")
"""Packages that import nothing of cyborg but themselves."""


def _cyborg_imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.add(node.module)
    return {name for name in found if name == "cyborg" or name.startswith("cyborg.")}


@pytest.mark.parametrize("package", INDEPENDENT)
def test_independent_packages_import_only_themselves(package: str) -> None:
    for path in sorted((SOURCE / package).rglob("*.py")):
        for name in _cyborg_imports(path):
            assert name.startswith(f"cyborg.{package}"), f"{path} imports {name}"


def test_modules_stay_small() -> None:
    for path in sorted(SOURCE.rglob("*.py")):
        lines = len(path.read_text().splitlines())
        assert lines <= 420, f"{path} has {lines} lines; split it"


ALLOWED = {"interfaces": ("cyborg.interfaces", "cyborg.bus"),
           "nav": ("cyborg.nav", "cyborg.bus", "cyborg.interfaces"),
           "sim": ("cyborg.sim", "cyborg.nav", "cyborg.bus", "cyborg.interfaces"),
           "nodes": ("cyborg.nodes", "cyborg.bt", "cyborg.bus", "cyborg.nav.geometry",
                     "cyborg.interfaces"),
           "monitor": ("cyborg.monitor", "cyborg.bus", "cyborg.bt.dot", "cyborg.bt.status",
                       "cyborg.bt.json_text", "cyborg.interfaces"),
           "vision": ("cyborg.vision", "cyborg.bus", "cyborg.interfaces")}
"""The contracts (topic, service and action names, types, constants) build only on the bus, so
that both sides of each can import them; navigation may use the bus (its services); the
simulator builds on navigation and the bus; the robot's nodes glue the engine to the bus, with
navigation's pose types (not its planner); the monitor watches trees over the bus and borrows
only the engine's DOT writer, statuses and JSON-text checks; vision publishes and subscribes on
the bus and knows nothing of trees or navigation. All but the contracts use the contracts."""


@pytest.mark.parametrize("package", sorted(ALLOWED))
def test_layered_packages_import_only_what_they_build_on(package: str) -> None:
    for path in sorted((SOURCE / package).rglob("*.py")):
        for name in _cyborg_imports(path):
            assert name.startswith(ALLOWED[package]), f"{path} imports {name}"
