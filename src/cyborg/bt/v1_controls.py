"""behavior3 v1's flow-control nodes: composites and decorators with behavior3-ts semantics.

behavior3-ts runs a tree as a stack machine: a RUNNING node is resumed on the next tick and,
when it finishes, its parent carries on from there in the same tick. cyborg re-ticks from the
root instead, so each node here keeps in its memory where it was (the branch an IfElse took,
the Case a Switch is in, the children a Parallel has seen finish) and resumes there. The
result is the same sequence of ticks, results and blackboard writes as in behavior3-ts.

Differences, all deliberate:

* **ERROR** in cyborg means a node's code raised, which in behavior3-ts interrupts the whole
  tree. So a child's ERROR ends these composites at once (RUNNING siblings halted) and is
  returned; behavior3-ts's rarer ``error`` *status* has no separate counterpart.
* **Loops are bounded per tick.** behavior3-ts re-runs a child that finishes at once within the
  same tick (Repeat ``count: 3`` around an action does all three in one tick), and an unlimited
  Repeat around such a child never returns. Here such loops run at most
  :data:`MAX_LOOPS_PER_TICK` times in a tick, then return RUNNING and go on next tick.
* **Halting**: a child that behavior3-ts would drop from its stack (a Race's losers, a
  Watchdog's branch when the guard fails) is halted, so its ``on_halt`` can cancel what it
  started.
"""

from __future__ import annotations

import math

from typing_extensions import override

from cyborg.bt.node import Action, Composite, Decorator
from cyborg.bt.properties import OptionalLoopCount
from cyborg.bt.status import ERROR, FAILURE, RUNNING, SUCCESS, NodeError, Status
from cyborg.bt.v1_data import array_input, oneof

MAX_LOOPS_PER_TICK = 1000
"""Most times Repeat (and ForEach, Filter) re-run a child that finishes at once, per tick."""


def _exactly(node: Composite, *counts: int) -> list[str]:
    if len(node.children) in counts:
        return []
    wanted = " or ".join(str(count) for count in counts)
    return [f"{type(node).__name__} takes {wanted} children, not {len(node.children)}"]


class IfElse(Composite):
    """Ticks child 1 (the condition) until it finishes, then the branch it chose.

    SUCCESS chooses child 2, FAILURE child 3 (none: FAILURE, as in behavior3lua); the branch's
    status is returned. A RUNNING branch is resumed without testing the condition again.
    """

    def check(self) -> list[str]:
        """One problem unless there are 2 or 3 children: condition, SUCCESS and FAILURE branch."""
        return _exactly(self, 2, 3)

    def on_start(self) -> None:
        """Starts the activation at the condition."""
        self.memory["branch"] = 0

    @override
    def tick(self) -> Status:
        children = self.children
        branch: int = self.memory["branch"]
        if branch == 0:
            status = children[0].execute()
            if status is RUNNING or status is ERROR:
                return status
            branch = self.memory["branch"] = 1 if status is SUCCESS else 2
            if branch >= len(children):
                return FAILURE
        return children[branch].execute()


class ParallelAll(Composite):
    """behavior3 v1's Parallel: ticks every unfinished child each tick, until all finish.

    Then SUCCESS, whatever their results; RUNNING until then. (cyborg's own Parallel counts
    successes and failures against thresholds; a v1 ``Parallel`` is this node.)
    """

    def on_start(self) -> None:
        """Marks every child unfinished for the new activation."""
        self.memory["finished"] = [False] * len(self.children)

    def tick(self) -> Status:
        """Ticks the unfinished children; a child's ERROR halts the others and is returned."""
        finished: list[bool] = self.memory["finished"]
        for index, child in enumerate(self.children):
            if finished[index]:
                continue
            status = child.execute()
            if status is ERROR:
                self.halt_children()
                return ERROR
            finished[index] = status is not RUNNING
        return SUCCESS if all(finished) else RUNNING


class Race(Composite):
    """Ticks every child still in the race each tick; the first SUCCESS wins and is returned."""

    def on_start(self) -> None:
        """Puts every child back in the race."""
        self.memory["failed"] = [False] * len(self.children)

    def tick(self) -> Status:
        """A SUCCESS (or ERROR) halts the others; a child that fails drops out; all out: FAILURE."""
        failed: list[bool] = self.memory["failed"]
        for index, child in enumerate(self.children):
            if failed[index]:
                continue
            status = child.execute()
            if status is SUCCESS or status is ERROR:
                self.halt_children()
                return status
            failed[index] = status is FAILURE
        return FAILURE if all(failed) else RUNNING


class Case(Composite):
    """A condition (child 1) and a branch (child 2), run by the :class:`Switch` above it.

    It ticks the condition until it finishes; on SUCCESS it is :attr:`matched` and ticks the
    branch, returning the branch's status; on FAILURE it returns FAILURE unmatched.
    """

    def check(self) -> list[str]:
        """One problem unless there are exactly 2 children: the condition and the branch."""
        return _exactly(self, 2)

    @property
    def matched(self) -> bool:
        """True once the condition succeeded in the current activation."""
        return bool(self.memory.get("matched"))

    def on_start(self) -> None:
        """Starts the activation unmatched, at the condition."""
        self.memory["matched"] = False

    def tick(self) -> Status:
        """Raises :class:`NodeError` (ERROR) unless the parent is a :class:`Switch`."""
        if not isinstance(self.parent, Switch):
            raise NodeError(f"a Case runs only as a child of a Switch, not of "
                               f"{type(self.parent).__name__}")
        if not self.memory["matched"]:
            status = self.children[0].execute()
            if status is not SUCCESS:
                return status
            self.memory["matched"] = True
        return self.children[1].execute()


class Switch(Composite):
    """Tries the :class:`Case` children in order; the first whose condition succeeds runs.

    Its branch's status is returned; FAILURE when no condition succeeds. A RUNNING condition or
    branch is resumed on the next tick, the earlier Cases not tried again.
    """

    def check(self) -> list[str]:
        """One problem for each child that is not a :class:`Case`."""
        return [f"Switch takes only Case children; child {number} is a "
                f"{type(child).__name__}" for number, child in enumerate(self.children, 1)
                if not isinstance(child, Case)]

    def on_start(self) -> None:
        """Starts the activation at the first Case."""
        self.memory["case"] = 0

    @override
    def tick(self) -> Status:
        children = self.children
        for index in range(self.memory["case"], len(children)):
            case = children[index]
            status = case.execute()
            if status is RUNNING:
                self.memory["case"] = index
                return RUNNING
            if status is ERROR or (isinstance(case, Case) and case.matched):
                return status
        return FAILURE


class Watchdog(Composite):
    """Checks a guard (child 1) on every tick while a branch (child 2) runs.

    Guard SUCCESS: tick or resume the branch and return its status. Guard FAILURE: halt the
    branch, give the fallback (child 3) one tick (halting whatever it leaves running) and
    return FAILURE. The guard must finish in one tick; a RUNNING guard raises (ERROR).
    """

    def check(self) -> list[str]:
        """One problem unless there are exactly 3 children: the guard, branch and fallback."""
        return _exactly(self, 3)

    @override
    def tick(self) -> Status:
        guard, branch, fallback = self.children
        status = guard.execute()
        if status is RUNNING:
            guard.halt()
            branch.halt()
            raise NodeError("the guard (first child) returned RUNNING; a Watchdog's guard "
                               "must finish in the tick it starts")
        if status is not SUCCESS:
            branch.halt()
            if status is ERROR:
                return ERROR
            fallback.execute()
            fallback.halt()
            return FAILURE
        return branch.execute()


class Once(Decorator):
    """Runs the child to completion once; that completion (SUCCESS or FAILURE) returns SUCCESS.

    Every later tick returns FAILURE without ticking the child. Being halted before the child
    finished does not count; the mark lasts until the tree is rebuilt.
    """

    @override
    def tick(self) -> Status:
        if self.memory.get("done"):
            return FAILURE
        status = self.child.execute()
        if status is RUNNING or status is ERROR:
            return status
        self.memory["done"] = True
        return SUCCESS


class AlwaysRunning(Decorator):
    """Ticks the child and returns RUNNING, whatever it returns (ERROR excepted)."""

    @override
    def tick(self) -> Status:
        return ERROR if self.child.execute() is ERROR else RUNNING


class Assert(Decorator):
    """Passes the child's SUCCESS or RUNNING; else raises NodeError(``message``): ERROR."""

    def __init__(self, message: str = "") -> None:
        self.message = message

    @override
    def tick(self) -> Status:
        status = self.child.execute()
        if status is SUCCESS or status is RUNNING:
            return status
        raise NodeError(f"{self.message or 'assertion failed'} (the child returned "
                             f"{status.label})")


class Repeat(Decorator):
    """Runs the child ``count`` times in a row (none: without end); SUCCESS after the last.

    A FAILURE (or ERROR) of the child stops the loop and is returned. ``count`` is the arg, or
    the ``count`` input when bound (oneof).
    """

    inputs = ("count?",)

    def __init__(self, count: OptionalLoopCount = None) -> None:
        self.count = count

    def on_start(self) -> None:
        """Starts the activation's count of runs at 0."""
        self.memory["done"] = 0

    def tick(self) -> Status:
        """Reruns a child that succeeds at once, up to :data:`MAX_LOOPS_PER_TICK` times a tick."""
        count = oneof(self, "count", self.count, math.inf)
        memory = self.memory
        for _ in range(MAX_LOOPS_PER_TICK):
            if memory["done"] >= count:
                return SUCCESS
            status = self.child.execute()
            if status is not SUCCESS:
                return status
            memory["done"] += 1
        return RUNNING


class RetryUntilSuccess(Decorator):
    """Tries the child until it succeeds (SUCCESS), at most ``count`` tries (none: no end).

    FAILURE when the last try did not succeed. A try that ends at once is followed by the next
    try on the next tick; a try that ran for several ticks is followed by the next one in the
    tick it ended, as in behavior3-ts. ``count`` is the arg, or the ``count`` input when bound.
    """

    inputs = ("count?",)
    _goal: Status = SUCCESS

    def __init__(self, count: OptionalLoopCount = None) -> None:
        self.count = count

    def on_start(self) -> None:
        """Starts the activation's count of tries at 0."""
        self.memory["tries"] = 0

    def _outcome(self, status: Status) -> Status:
        if status is ERROR or status is RUNNING:
            return status
        return SUCCESS if status is self._goal else RUNNING  # RUNNING: try again

    @override
    def tick(self) -> Status:
        memory, child = self.memory, self.child
        if memory["tries"] == 0:
            memory["tries"] = 1
            return self._outcome(child.execute())
        if child.status is RUNNING:
            status = child.execute()
            if status is RUNNING or status is ERROR or status is self._goal:
                return self._outcome(status)
        if memory["tries"] >= oneof(self, "count", self.count, math.inf):
            return FAILURE
        memory["tries"] += 1
        return self._outcome(child.execute())


class RetryUntilFailure(RetryUntilSuccess):
    """As :class:`RetryUntilSuccess`, but a try succeeds when the child fails (SUCCESS)."""

    _goal = FAILURE


class ForEach(Decorator):
    """Runs the child to completion for each element of the ``array`` input, in order.

    The element goes to ``item`` (its index to ``index``) first; SUCCESS after the last one. A
    FAILURE (or ERROR) of the child stops the loop and is returned. Both outputs are deleted
    when the loop ends, as behavior3-ts does.
    """

    inputs = ("array",)
    outputs = ("item", "index?")

    def on_start(self) -> None:
        """Starts the activation at the first element."""
        self.memory["next"] = 0

    def _finish(self, status: Status) -> Status:
        self.write("item", None)
        self.write("index", None)
        return status

    def tick(self) -> Status:
        """Runs elements the child finishes at once, up to :data:`MAX_LOOPS_PER_TICK` a tick."""
        array, memory = array_input(self, "array"), self.memory
        for _ in range(MAX_LOOPS_PER_TICK):
            index = memory["next"]
            if self.child.status is not RUNNING:  # a new element, not a RUNNING one resumed
                if index >= len(array):
                    return self._finish(SUCCESS)
                self.write("item", array[index])
                self.write("index", index)
            status = self.child.execute()
            if status is RUNNING:
                return RUNNING
            if status is not SUCCESS:
                return self._finish(status)
            memory["next"] = index + 1
        return RUNNING


class Filter(Decorator):
    """Runs the child once per element of the ``array`` input, the element in ``item``.

    The elements it succeeded on go, in order, to ``result`` as a new list; SUCCESS if there
    are any, else FAILURE; ``item`` is deleted at the end. After a RUNNING child, cyborg resumes
    at that element (behavior3-ts restarts from the first, keeping what it had collected).
    """

    inputs = ("array",)
    outputs = ("item", "result")

    def on_start(self) -> None:
        """Starts the activation at the first element, with nothing kept."""
        self.memory["next"] = 0
        self.memory["kept"] = []

    def tick(self) -> Status:
        """Runs elements the child finishes at once, up to :data:`MAX_LOOPS_PER_TICK` a tick."""
        array, memory = array_input(self, "array"), self.memory
        kept: list[object] = memory["kept"]
        for _ in range(MAX_LOOPS_PER_TICK):
            index = memory["next"]
            if self.child.status is not RUNNING:
                if index >= len(array):
                    self.write("item", None)
                    self.write("result", kept if array else None)
                    return SUCCESS if kept else FAILURE
                self.write("item", array[index])
            status = self.child.execute()
            if status is RUNNING or status is ERROR:
                return status
            if status is SUCCESS:
                kept.append(array[index])
            memory["next"] = index + 1
        return RUNNING


class WaitForCount(Action):
    """RUNNING for ``tick`` ticks, then SUCCESS (behavior3lua; at least one tick)."""

    def __init__(self, tick: int) -> None:
        self.ticks = tick

    def on_start(self) -> None:
        """Starts the activation's count of ticks at 0."""
        self.memory["ticked"] = 0

    @override
    def tick(self) -> Status:
        self.memory["ticked"] += 1
        return SUCCESS if self.memory["ticked"] > max(self.ticks, 1) else RUNNING
