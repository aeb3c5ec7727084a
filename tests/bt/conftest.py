"""Fixtures for the tests of behavior3 v1's stock nodes (tests/bt/test_v1_*.py).

Node ids restart at 1 for every test (autouse: a no-op for tests that build no v1 nodes), and
``lines`` collects what the Log nodes print (see tests/bt/v1_samples.py).
"""

from __future__ import annotations

import logging
from typing import Any

import pytest

from tests.bt.v1_samples import LogLines, fresh_ids


@pytest.fixture(autouse=True)
def _fresh_ids() -> None:
    fresh_ids()


@pytest.fixture
def lines() -> Any:
    handler = LogLines()
    logger = logging.getLogger("cyborg.bt.log")
    logger.addHandler(handler)
    level = logger.level
    logger.setLevel(logging.DEBUG)
    yield handler
    logger.removeHandler(handler)
    logger.setLevel(level)
