"""``OncePerObject{key, seconds, gap, near}``: do something once per object, not every tick.

A greeting drawn as ``Sequence[ObjectDetected, FaceObject, Say]`` under a Priority says hello
on every tick the person stays near. This decorator makes it once: it reads the object that
``ClosestObject`` wrote to the blackboard entry ``key`` (default ``closest``: a mapping with the
tracker's ``id``) and ticks its child only when

* that object's id has not had the child succeed within the last ``seconds`` (default 60),
* nothing at all has had the child succeed within the last ``gap`` seconds (default 10; 0: no
  such pause), so a crowd walking by is not greeted one after the other without pause, and
* it is not within ``near`` metres (default 2; 0: ids only) of where an object done within
  ``seconds`` was last seen. The tracker gives someone it lost sight of for a few seconds
  (the robot turned away) a new id; by place they are still the person greeted, and so is
  the group standing with them: a group is greeted once.

Otherwise, or when the entry holds no object (None, not a mapping, or no ``id``), it returns
FAILURE without ticking the child, and a Priority above it goes on to its next branch (the
patrol). The decision is taken when an activation begins: while the child runs (turning toward
the person) it keeps ticking it even if ``ClosestObject`` meanwhile names someone else. When the
child succeeds the object's id and the time are remembered; a child that fails (the person
walked away before the robot faced them) is not, so the object may be tried again.

While an object done lately is named by the entry (the robot still sees them), its place is
followed, and a new id found near it inherits its time. Someone who comes back after walking
out of sight elsewhere is a new object: greeted again after ``gap``. Times are the tree's
clock (simulated time under a simulator). The memory is the node's, so it lasts while the
tree's blackboard does; objects are forgotten ``seconds`` after they were done, and a clock
that went back (a restarted simulation) forgets everything.

In behavior3editor: a decorator (declare it in ``custom_nodes`` with the category
``decorator``), its child the Sequence that does the greeting.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from typing_extensions import override

from cyborg.bt import FAILURE, SUCCESS, Decorator, Status, register

SECONDS = 60.0
"""How long the same object is not done again, unless told otherwise."""
GAP = 10.0
"""How long after any success nothing is done again, unless told otherwise."""

NEAR = 2.0
"""How close (m) to where a done object was last seen another id counts as that object."""

ObjectId = int | str
"""An object's id as the blackboard entry gives it (the tracker's are ints)."""
Position = tuple[float, float]
"""A map position, metres."""


@dataclass
class Done:
    """An object the child succeeded for: when, and where it was last seen since."""

    when: float
    """The tree's time of the success."""
    where: Position | None
    """Its map position when last named by the entry (None: the entry had none)."""


@register
class OncePerObject(Decorator):
    """Ticks its child for the object in ``key`` only if not done lately; see the module."""

    def __init__(self, key: str = "closest", seconds: float = SECONDS, gap: float = GAP,
                 near: float = NEAR) -> None:
        if not key:
            raise ValueError("key is empty: name the blackboard entry ClosestObject writes")
        for name, value in (("seconds", seconds), ("gap", gap), ("near", near)):
            if not isinstance(value, int | float) or math.isnan(value) or value < 0:
                unit = "metres" if name == "near" else "seconds"
                raise ValueError(f"{name} must be a number of {unit} >= 0, not {value!r}")
        self.key, self.seconds, self.gap = key, float(seconds), float(gap)
        self.near = float(near)
        self.reason = ""
        """Why the child was not ticked, the last time it was not."""

    def done_lately(self) -> dict[ObjectId, Done]:
        """Object id -> when the child last succeeded for it and where it was last seen."""
        memory = self.memory
        done: dict[ObjectId, Done] = memory.setdefault("done", {})
        now = self.now
        if any(item.when > now for item in done.values()) or memory.get("last", -math.inf) > now:
            done.clear()  # the clock went back
            memory["last"] = -math.inf
        for object_id in [key for key, item in done.items() if now - item.when >= self.seconds]:
            del done[object_id]
        return done

    def on_start(self) -> None:
        """Decides whether this activation ticks the child, for which object."""
        self.memory["object"] = self._choose()

    def _choose(self) -> tuple[ObjectId, Position | None] | None:
        entry: Any = self.blackboard.get(self.key)
        object_id = entry.get("id") if isinstance(entry, Mapping) else None
        if not isinstance(object_id, int | str) or isinstance(object_id, bool):
            self.reason = f"the blackboard's {self.key!r} holds no object"
            return None
        where = _position(entry)
        done = self.done_lately()
        now = self.now
        same = object_id if object_id in done else self._done_near(done, where)
        if same is not None:
            earlier = done[same]
            done[object_id] = Done(earlier.when, where or earlier.where)  # follow them
            self.reason = (f"object {object_id} was done {now - earlier.when:.0f} s ago "
                           f"(again after {self.seconds:g} s)")
            return None
        last = self.memory.get("last", -math.inf)
        if now - last < self.gap:
            self.reason = f"something was done {now - last:.0f} s ago (next after {self.gap:g} s)"
            return None
        self.reason = ""
        return object_id, where

    def _done_near(self, done: dict[ObjectId, Done], where: Position | None) -> ObjectId | None:
        """The done object last seen nearest ``where``, within ``near``; None if none is."""
        if where is None or not self.near:
            return None
        found, best = None, self.near
        for object_id, item in done.items():
            if item.where is not None:
                distance = math.dist(where, item.where)
                if distance <= best:
                    found, best = object_id, distance
        return found

    @override
    def tick(self) -> Status:
        chosen = self.memory.get("object")
        if chosen is None:
            return FAILURE
        status = self.child.execute()
        if status is SUCCESS:
            now = self.now
            object_id, where = chosen
            self.done_lately()[object_id] = Done(now, where)
            self.memory["last"] = now
        return status


def _position(entry: Mapping[str, Any]) -> Position | None:
    """The entry's map position (``x``, ``y``) when it has a finite one."""
    x, y = entry.get("x"), entry.get("y")
    if isinstance(x, int | float) and isinstance(y, int | float) and math.isfinite(x + y):
        return float(x), float(y)
    return None
