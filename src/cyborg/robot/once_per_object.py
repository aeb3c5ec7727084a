"""``OncePerObject{key, seconds, gap}``: do something once per tracked object, not on every tick.

A greeting drawn as ``Sequence[ObjectDetected, FaceObject, Say]`` under a Priority says hello
on every tick the person stays near. This decorator makes it once: it reads the object that
``ClosestObject`` wrote to the blackboard entry ``key`` (default ``closest``: a mapping with the
tracker's ``id``) and ticks its child only when

* that object's id has not had the child succeed within the last ``seconds`` (default 60), and
* nothing at all has had the child succeed within the last ``gap`` seconds (default 10; 0: no
  such pause), so a crowd walking by is not greeted one after the other without pause.

Otherwise, or when the entry holds no object (None, not a mapping, or no ``id``), it returns
FAILURE without ticking the child, and a Priority above it goes on to its next branch (the
patrol). The decision is taken when an activation begins: while the child runs (turning toward
the person) it keeps ticking it even if ``ClosestObject`` meanwhile names someone else. When the
child succeeds the object's id and the time are remembered; a child that fails (the person
walked away before the robot faced them) is not, so the object may be tried again.

Times are the tree's clock (simulated time under a simulator). The memory is the node's, so it
lasts while the tree's blackboard does; ids the tracker stopped using are forgotten after
``seconds``, and a clock that went back (a restarted simulation) forgets everything. The
tracker gives a person who was out of sight for longer than its forget time a new id, so they
may be greeted again after ``gap``.

In behavior3editor: a decorator (declare it in ``custom_nodes`` with the category
``decorator``), its child the Sequence that does the greeting.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from typing_extensions import override

from cyborg.bt import FAILURE, SUCCESS, Decorator, Status, register

SECONDS = 60.0
"""How long the same object is not done again, unless told otherwise."""
GAP = 10.0
"""How long after any success nothing is done again, unless told otherwise."""

ObjectId = int | str
"""An object's id as the blackboard entry gives it (the tracker's are ints)."""


@register
class OncePerObject(Decorator):
    """Ticks its child for the object in ``key`` only if not done lately; see the module."""

    def __init__(self, key: str = "closest", seconds: float = SECONDS, gap: float = GAP) -> None:
        if not key:
            raise ValueError("key is empty: name the blackboard entry ClosestObject writes")
        for name, value in (("seconds", seconds), ("gap", gap)):
            if not isinstance(value, int | float) or math.isnan(value) or value < 0:
                raise ValueError(f"{name} must be a number of seconds >= 0, not {value!r}")
        self.key, self.seconds, self.gap = key, float(seconds), float(gap)
        self.reason = ""
        """Why the child was not ticked, the last time it was not."""

    def done_lately(self) -> dict[ObjectId, float]:
        """Object id -> when the child last succeeded for it (tree clock), within ``seconds``."""
        memory = self.memory
        done: dict[ObjectId, float] = memory.setdefault("done", {})
        now = self.now
        if any(when > now for when in done.values()) or memory.get("last", -math.inf) > now:
            done.clear()  # the clock went back
            memory["last"] = -math.inf
        for object_id in [key for key, when in done.items() if now - when >= self.seconds]:
            del done[object_id]
        return done

    def on_start(self) -> None:
        """Decides whether this activation ticks the child, for which object."""
        self.memory["object"] = self._choose()

    def _choose(self) -> ObjectId | None:
        entry: Any = self.blackboard.get(self.key)
        object_id = entry.get("id") if isinstance(entry, Mapping) else None
        if not isinstance(object_id, int | str) or isinstance(object_id, bool):
            self.reason = f"the blackboard's {self.key!r} holds no object"
            return None
        done = self.done_lately()
        now = self.now
        if object_id in done:
            self.reason = (f"object {object_id} was done {now - done[object_id]:.0f} s ago "
                           f"(again after {self.seconds:g} s)")
            return None
        last = self.memory.get("last", -math.inf)
        if now - last < self.gap:
            self.reason = f"something was done {now - last:.0f} s ago (next after {self.gap:g} s)"
            return None
        self.reason = ""
        return object_id

    @override
    def tick(self) -> Status:
        object_id = self.memory.get("object")
        if object_id is None:
            return FAILURE
        status = self.child.execute()
        if status is SUCCESS:
            now = self.now
            self.done_lately()[object_id] = now
            self.memory["last"] = now
        return status
