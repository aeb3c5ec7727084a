"""Shared test fixtures: where the project's shared data lives, and a headless Chromium.

The sample trees, maps and models are read from ``../shared`` beside the checkout, or from the
folder named by the ``CYBORG_SHARED`` environment variable. ``browser`` is Debian's Chromium
under Playwright, one per test module (tests/monitor/browser.py launches it).
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

import cyborg.robot  # noqa: F401  (the robot's nodes are part of every test's baseline)
from cyborg.bt import registry

if TYPE_CHECKING:
    from playwright.sync_api import Browser


def shared_dir() -> Path:
    path = Path(os.environ.get("CYBORG_SHARED", Path(__file__).resolve().parents[2] / "shared"))
    if not path.is_dir():
        raise FileNotFoundError(f"shared data folder {path} not found; set CYBORG_SHARED")
    return path


@pytest.fixture
def shared() -> Path:
    return shared_dir()


@pytest.fixture(scope="module")
def browser() -> Iterator[Browser]:
    from playwright.sync_api import sync_playwright  # only where a test asks for a browser

    from tests.monitor.browser import launch_chromium

    with sync_playwright() as playwright:
        chromium = launch_chromium(playwright)
        yield chromium
        chromium.close()


@pytest.fixture(autouse=True, scope="session")
def _models_from_shared() -> Iterator[None]:
    """Programs the tests start (``cyborg up``, ``cyborg detect``) find the shared detector model
    instead of downloading one."""
    if "CYBORG_MODELS" not in os.environ and (shared_dir() / "models").is_dir():
        os.environ["CYBORG_MODELS"] = str(shared_dir() / "models")
        yield
        del os.environ["CYBORG_MODELS"]
    else:
        yield


@pytest.fixture(autouse=True)
def _restore_registered_nodes() -> Iterator[None]:
    """Nodes a test registers with @register (overriding a name or not) do not leak into other
    tests."""
    saved, overridden = dict(registry._REGISTERED._types), set(registry._REGISTERED._overridden)
    yield
    registry._REGISTERED._types.clear()
    registry._REGISTERED._types.update(saved)
    registry._REGISTERED._overridden.clear()
    registry._REGISTERED._overridden.update(overridden)


TIERS = ("unit", "bus", "subprocess", "browser", "system", "soak")
"""The tiers every test falls in, marked automatically (pyproject.toml registers them):
``scripts/test.sh --quick`` runs the unit tier; the whole suite runs them all."""


def _tier_of(item: pytest.Item) -> str:
    """The tier of one test, from where it is and what it uses (its fixtures, its module)."""
    path = Path(str(item.fspath))
    module = getattr(item, "module", None)
    names = vars(module) if module is not None else {}
    fixtures = set(getattr(item, "fixturenames", ()))
    if item.get_closest_marker("soak") is not None:
        return "soak"
    if "system" in path.parts or path.name == "test_doc_commands.py":
        return "system"
    if "browser" in fixtures or "browser" in path.name or "sync_playwright" in names:
        return "browser"
    if "subprocess" in names or "Popen" in names:
        return "subprocess"
    if "bus" in fixtures or "Context" in names or "BusConfig" in names:
        return "bus"
    if item.get_closest_marker("heavy") is not None:
        return "system"
    return "unit"


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Marks each test with its tier (see :data:`TIERS`)."""
    for item in items:
        tier = _tier_of(item)
        if item.get_closest_marker(tier) is None:
            item.add_marker(getattr(pytest.mark, tier))
