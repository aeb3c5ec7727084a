"""Decorators: nodes with one child whose result they shape.

Times are in milliseconds, as the editor writes them, and are read from the tree's clock at the
start of each tick, so they run on simulated time as well as on the wall clock.

Loops never spin inside one tick: a repeating decorator ticks its child at most once per tick
and returns RUNNING between iterations. Counters that must survive activations (Limiter,
RunOnce) live in node memory and are not reset when the node starts again.
"""

from __future__ import annotations

from typing_extensions import override

from cyborg.bt.node import Decorator
from cyborg.bt.properties import LoopCount
from cyborg.bt.status import ERROR, FAILURE, RUNNING, SUCCESS, Status


class Inverter(Decorator):
    """Swaps SUCCESS and FAILURE; RUNNING and ERROR pass through."""

    @override
    def tick(self) -> Status:
        status = self.child.execute()
        if status is SUCCESS:
            return FAILURE
        if status is FAILURE:
            return SUCCESS
        return status


class ForceSuccess(Decorator):
    """SUCCESS whenever the child completes with SUCCESS or FAILURE; RUNNING and ERROR pass."""

    @override
    def tick(self) -> Status:
        status = self.child.execute()
        return SUCCESS if status is FAILURE else status


class ForceFailure(Decorator):
    """FAILURE whenever the child completes with SUCCESS or FAILURE; RUNNING and ERROR pass."""

    @override
    def tick(self) -> Status:
        status = self.child.execute()
        return FAILURE if status is SUCCESS else status


def _check_loop(field: str, value: int) -> list[str]:
    if value == -1 or value >= 1:
        return []
    return [f"{field} must be -1 (forever) or at least 1, not {value}"]


class Repeater(Decorator):
    """Ticks the child again each time it completes, ``maxLoop`` times (``-1``: forever).

    A ``maxLoop`` of infinity (``1e999`` in JSON) is read as ``-1``, with a note.

    Completion with SUCCESS or FAILURE both count as one loop; ERROR stops the loop and is
    returned. After the last loop the child's last status is returned. One loop per tick.
    """

    _until: Status | None = None  # stop early when the child returns this

    def __init__(self, max_loop: LoopCount = -1) -> None:
        self.max_loop = max_loop

    def check(self) -> list[str]:
        """The decorator's problems, plus a ``maxLoop`` neither ``-1`` nor at least 1."""
        return super().check() + _check_loop("maxLoop", self.max_loop)

    def on_start(self) -> None:
        """Starts the new activation's count of loops at 0."""
        self.memory["loops"] = 0

    @override
    def tick(self) -> Status:
        status = self.child.execute()
        if status is RUNNING or status is ERROR or status is self._until:
            return status
        memory = self.memory
        memory["loops"] += 1
        if self.max_loop != -1 and memory["loops"] >= self.max_loop:
            return status
        return RUNNING


class RepeatUntilFailure(Repeater):
    """Repeats while the child succeeds; returns FAILURE once it fails.

    After ``maxLoop`` successes (``-1``: no limit) it returns SUCCESS.
    """

    _until = FAILURE


class RepeatUntilSuccess(Repeater):
    """Repeats while the child fails; returns SUCCESS once it succeeds.

    After ``maxLoop`` failures (``-1``: no limit) it returns FAILURE.
    """

    _until = SUCCESS


class Retry(RepeatUntilSuccess):
    """Retries a failing child up to ``maxAttempts`` times in all (``-1``: forever)."""

    def __init__(self, max_attempts: LoopCount = 3) -> None:
        self.max_loop = max_attempts

    def check(self) -> list[str]:
        """The decorator's problems, plus a ``maxAttempts`` neither ``-1`` nor at least 1."""
        return Decorator.check(self) + _check_loop("maxAttempts", self.max_loop)


class Limiter(Decorator):
    """Lets the child complete at most ``maxLoop`` times; after that returns FAILURE.

    The count lives in node memory and survives activations, so the limit holds across the
    whole run (behavior3's Limiter reset it on every activation and never limited).
    """

    def __init__(self, max_loop: int = 1) -> None:
        self.max_loop = max_loop

    def check(self) -> list[str]:
        """The decorator's problems, plus a negative ``maxLoop``."""
        problems = super().check()
        if self.max_loop < 0:
            problems.append(f"maxLoop must be 0 or more, not {self.max_loop}")
        return problems

    @override
    def tick(self) -> Status:
        memory = self.memory
        completed = memory.get("completed", 0)
        if completed >= self.max_loop:
            return FAILURE
        status = self.child.execute()
        if status is not RUNNING:
            memory["completed"] = completed + 1
        return status


class Timeout(Decorator):
    """Fails if the child is still RUNNING ``milliseconds`` after the activation began.

    The deadline is checked *before* the child is ticked; when it has passed, the child is
    halted (its on_halt runs) and Timeout returns FAILURE.
    """

    _field = "milliseconds"

    def __init__(self, milliseconds: float) -> None:
        self.limit_ms = milliseconds

    def check(self) -> list[str]:
        """The decorator's problems, plus a limit that is not more than 0 ms."""
        problems = super().check()
        if not self.limit_ms > 0:
            problems.append(f"{self._field} must be more than 0 ms, not {self.limit_ms}")
        return problems

    def on_start(self) -> None:
        """Notes the activation's start (:attr:`now`) in ``memory["start"]``."""
        self.memory["start"] = self.now

    @override
    def tick(self) -> Status:
        if self.ms_since() >= self.limit_ms:
            self.child.halt()
            return FAILURE
        return self.child.execute()


class MaxTime(Timeout):
    """behavior3's name for :class:`Timeout`; the limit is ``maxTime`` in milliseconds."""

    _field = "maxTime"

    def __init__(self, max_time: float) -> None:
        self.limit_ms = max_time


class Delay(Decorator):
    """Waits ``milliseconds`` (RUNNING) before ticking the child, once per activation."""

    def __init__(self, milliseconds: float) -> None:
        self.delay_ms = milliseconds

    def check(self) -> list[str]:
        """The decorator's problems, plus a negative ``milliseconds``."""
        problems = super().check()
        if self.delay_ms < 0:
            problems.append(f"milliseconds must be 0 or more, not {self.delay_ms}")
        return problems

    def on_start(self) -> None:
        """Notes the activation's start (:attr:`now`) in ``memory["start"]``."""
        self.memory["start"] = self.now

    @override
    def tick(self) -> Status:
        if self.ms_since() < self.delay_ms:
            return RUNNING
        return self.child.execute()


class RunOnce(Decorator):
    """Ticks the child until it completes once, then returns that status without ticking.

    The remembered result lives in node memory; it is forgotten only when the tree is rebuilt.
    """

    @override
    def tick(self) -> Status:
        memory = self.memory
        result: Status | None = memory.get("result")
        if result is not None:
            return result
        status = self.child.execute()
        if status is not RUNNING:
            memory["result"] = status
        return status
