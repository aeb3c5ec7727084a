"""Composite nodes: Sequence, Priority, their memory variants, and Parallel.

Without memory (Sequence, Priority) the composite restarts from its first child on every tick,
so a higher-priority child can take over at any time; the child it replaces is halted at the
end of that tick. With memory (MemSequence, MemPriority) it resumes at the child that was
RUNNING, and starts from the first child only when a new activation begins. A
ResumingSequence goes one step further: halted while a child runs, it resumes at that child in
its next activation too (a patrol interrupted by a greeting goes on to the goal it was driving
to, not back to its first one).
"""

from __future__ import annotations

from typing_extensions import override

from cyborg.bt.node import Composite
from cyborg.bt.status import ERROR, FAILURE, RUNNING, SUCCESS, Status


class Sequence(Composite):
    """Ticks children in order; returns the first status that is not SUCCESS, else SUCCESS."""

    @override
    def tick(self) -> Status:
        for child in self.children:
            status = child.execute()
            if status is not SUCCESS:
                return status
        return SUCCESS


class Priority(Composite):
    """Ticks children in order; returns the first status that is not FAILURE, else FAILURE.

    Also known as Selector or Fallback.
    """

    @override
    def tick(self) -> Status:
        for child in self.children:
            status = child.execute()
            if status is not FAILURE:
                return status
        return FAILURE


class MemSequence(Composite):
    """A Sequence that resumes at the RUNNING child instead of re-checking earlier ones."""

    _continue: Status = SUCCESS

    def on_start(self) -> None:
        """Starts a new activation at the first child."""
        self.memory["running_child"] = 0

    def tick(self) -> Status:
        """Ticks children from the one left RUNNING (``memory["running_child"]``) on.

        Returns the first status that is not SUCCESS (for :class:`MemPriority`: FAILURE),
        noting the child's index when that status is RUNNING; else SUCCESS (FAILURE).
        """
        memory = self.memory
        children = self.children
        go_on = self._continue
        for index in range(memory["running_child"], len(children)):
            status = children[index].execute()
            if status is not go_on:
                if status is RUNNING:
                    memory["running_child"] = index
                return status
        return go_on


class ResumingSequence(MemSequence):
    """A MemSequence that keeps its place when it is halted.

    A MemSequence halted by a higher branch of a Priority (or by a mode change) starts again
    at its first child when it is ticked again; a ResumingSequence starts again at the child
    that was RUNNING when it was halted, which starts afresh (a ``MoveTo`` sends its goal
    again, a ``Wait`` waits its whole time). Only completing — every child succeeded, or one
    failed or raised — brings it back to its first child. Under a Repeater it is a round that
    interruptions do not restart: ``Priority[greet, Repeater[ResumingSequence[MoveTo A,
    MoveTo B, ...]]]`` drives on to the goal it was driving to after each greeting.

    The place is node memory, so it lasts as long as the tree's blackboard: a reloaded tree
    starts at its first child.
    """

    def on_start(self) -> None:
        """Starts a new activation where the last one was halted (the first child if none)."""
        self.memory.setdefault("running_child", 0)

    def tick(self) -> Status:
        """Ticks as a MemSequence; on completion the next activation starts at the first child."""
        status = super().tick()
        if status is not RUNNING:
            self.memory["running_child"] = 0
        return status


class MemPriority(MemSequence):
    """A Priority that resumes at the RUNNING child instead of re-trying earlier ones."""

    _continue = FAILURE


class Parallel(Composite):
    """Ticks all children every tick until enough of them succeed or fail.

    ``successThreshold`` children must succeed for SUCCESS, and ``failureThreshold`` failures
    give FAILURE; ``-1`` means "all children". Children that have completed in the current
    activation are not ticked again. When the result is decided, children still RUNNING are
    halted. If every child has completed and the success threshold was not reached, the result
    is FAILURE. A child's ERROR halts the others and is returned.
    """

    def __init__(self, success_threshold: int = -1, failure_threshold: int = 1) -> None:
        self.success_threshold = success_threshold
        self.failure_threshold = failure_threshold

    def check(self) -> list[str]:
        """One problem for each threshold that is neither ``-1`` nor 1 to the child count."""
        problems = []
        count = len(self.children)
        for field, value in (
            ("successThreshold", self.success_threshold),
            ("failureThreshold", self.failure_threshold),
        ):
            if value != -1 and not 1 <= value <= count:
                problems.append(f"{field} must be -1 (all) or 1..{count} (children), not {value}")
        return problems

    def _needed(self, threshold: int) -> int:
        return len(self.children) if threshold == -1 else threshold

    def on_start(self) -> None:
        """Forgets the results of the last activation: every child is ticked again."""
        self.memory["done"] = [None] * len(self.children)

    def tick(self) -> Status:
        """Ticks each child not yet completed in this activation, then counts the results.

        SUCCESS once ``successThreshold`` children have succeeded, else FAILURE once
        ``failureThreshold`` have failed or all have completed; a decided result halts the
        children still RUNNING. A child's ERROR halts the others and is returned at once,
        before the children after it are ticked.
        """
        done: list[Status | None] = self.memory["done"]
        successes = failures = 0
        for index, child in enumerate(self.children):
            status = done[index]
            if status is None:
                status = child.execute()
                if status is not RUNNING:
                    done[index] = status
            if status is SUCCESS:
                successes += 1
            elif status is FAILURE:
                failures += 1
            elif status is ERROR:
                self.halt_children()
                return ERROR
        if successes >= self._needed(self.success_threshold):
            result = SUCCESS
        elif failures >= self._needed(self.failure_threshold) or None not in done:
            result = FAILURE
        else:
            return RUNNING
        self.halt_children()
        return result
