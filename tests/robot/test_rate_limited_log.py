"""RateLimitedLog: a failure that repeats every tick is logged once per interval, counted."""

from __future__ import annotations

import logging

import pytest

from cyborg.robot.rate_limited_log import RateLimitedLog


class Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def test_repeats_are_counted_and_summarised(caplog: pytest.LogCaptureFixture) -> None:
    clock = Clock()
    limited = RateLimitedLog(logging.getLogger("test.limited"), interval=10.0, clock=clock)
    emitted = []
    for tenth in range(250):  # every tick for 25 s
        clock.now = tenth / 10
        emitted.append(limited.warning("unreachable", "MoveTo %s failed: %s", "room1", "gone"))
    assert [index for index, shown in enumerate(emitted) if shown] == [0, 100, 200]
    assert [record.getMessage() for record in caplog.records] == [
        "MoveTo room1 failed: gone",
        "MoveTo room1 failed: gone [99 more like this in the last 10 s]",
        "MoveTo room1 failed: gone [99 more like this in the last 10 s]"]
    assert {record.levelno for record in caplog.records} == {logging.WARNING}


def test_keys_are_independent_and_levels_kept(caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, "test.limited")
    clock = Clock()
    limited = RateLimitedLog(logging.getLogger("test.limited"), interval=5.0, clock=clock)
    assert limited.warning("a", "first a")
    assert limited.info("b", "first b")
    assert not limited.warning("a", "again a")
    clock.now = 30.0  # long after: shown, with what was left out
    assert limited.log(logging.ERROR, "a", "late a")
    assert [(record.levelno, record.getMessage()) for record in caplog.records] == [
        (logging.WARNING, "first a"), (logging.INFO, "first b"),
        (logging.ERROR, "late a [1 more like this in the last 30 s]")]


def test_a_message_with_a_percent_in_its_arguments_is_safe(
        caplog: pytest.LogCaptureFixture) -> None:
    clock = Clock()
    limited = RateLimitedLog(logging.getLogger("test.limited"), interval=1.0, clock=clock)
    limited.warning("k", "%s", "100% sure")
    limited.warning("k", "%s", "100% sure")
    clock.now = 2.0
    limited.warning("k", "%s", "100% sure")
    assert caplog.records[-1].getMessage() == "100% sure [1 more like this in the last 2 s]"
    limited.warning("plain", "at 20% charge")
    limited.warning("plain", "at 20% charge")
    clock.now = 4.0
    limited.warning("plain", "at 20% charge")
    assert caplog.records[-1].getMessage() == "at 20% charge [1 more like this in the last 2 s]"


def test_the_table_of_keys_stays_bounded() -> None:
    clock = Clock()
    limited = RateLimitedLog(logging.getLogger("test.limited"), interval=10.0, clock=clock,
                             max_keys=100)
    for number in range(10_000):
        clock.now = number / 10
        limited.warning(("node", number), "failed")
    assert len(limited) <= 100


def test_interval_must_be_positive() -> None:
    with pytest.raises(ValueError, match="interval"):
        RateLimitedLog(logging.getLogger("x"), interval=0.0)
    with pytest.raises(ValueError, match="interval"):
        RateLimitedLog(logging.getLogger("x"), interval=float("nan"))
