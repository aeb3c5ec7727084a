"""Fixtures the monitor's browser tests share: columbia's map blob and a stand-in monitor
serving it (the Chromium, one per module, is tests/conftest.py's; a module that needs another
browser defines its own)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from cyborg.monitor.map_store import map_key
from cyborg.nav.arnl_map import ArnlMap, read_map
from tests.conftest import shared_dir
from tests.monitor.map_page import BROKEN_KEY, StandInMonitor, first_messages, pack_map_blob


@pytest.fixture(scope="module")
def columbia() -> tuple[ArnlMap, bytes, str]:
    arnl_map = read_map(shared_dir() / "maps" / "columbia.map")
    blob = pack_map_blob(arnl_map)
    return arnl_map, blob, map_key(blob)


@pytest.fixture
def server(columbia: tuple[ArnlMap, bytes, str]) -> Iterator[StandInMonitor]:
    arnl_map, blob, key = columbia
    with StandInMonitor({key: blob, BROKEN_KEY: b"GIF89a, not a map at all"},
                        on_map=first_messages(arnl_map, key)) as running:
        yield running
