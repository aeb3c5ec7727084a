"""What a mode machine tells its watchers: each transition, each answer, each tick's mode.

* :class:`Transition` — one change of mode, as the transition log keeps it and listeners get it:
  from, to, why, when (on the tree clock), and how (:class:`Trigger`).
* :class:`Decision` — the answer to a request, a force or an event: taken or refused, and why.
* :class:`ModeTick` — the machine's snapshot of one tick: which mode's tree ticked, its
  :class:`~cyborg.bt.snapshot.TickSnapshot`, and the transition that tick led to, if any.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from cyborg.bt.snapshot import TickSnapshot


class Trigger(StrEnum):
    """What made a transition fire."""

    CONDITION = "condition"
    """A ``when`` condition was true after a tick."""
    EVENT = "event"
    """An event was published (:meth:`ModeMachine.fire_event`)."""
    REQUEST = "request"
    """A request allowed by an ``on_request`` transition (:meth:`ModeMachine.request`)."""
    TIMEOUT = "timeout"
    """The mode's ``max_time`` ran out; it went to its ``then``."""
    FORCE = "force"
    """An operator forced it (:meth:`ModeMachine.force`), past guards, dwell and hold."""


@dataclass(frozen=True)
class Transition:
    """One change of mode."""

    source: str
    """The mode left."""
    target: str
    """The mode entered."""
    reason: str
    """Why, in words: the condition, the event, the requester's reason, the timeout."""
    time: float
    """The tree clock's time of the change, in seconds."""
    trigger: Trigger
    number: int | None = None
    """The transition's number in the mode file; None for a timeout or a force."""

    def to_json(self) -> dict[str, object]:
        """The transition as a JSON object, for monitors and logs."""
        return {"from": self.source, "to": self.target, "reason": self.reason,
                "time": self.time, "trigger": self.trigger.value, "number": self.number}


@dataclass(frozen=True)
class Decision:
    """The answer to :meth:`~ModeMachine.request`, :meth:`~ModeMachine.force` or an event."""

    accepted: bool
    """Whether the machine is now in the mode asked for (True also when it already was)."""
    message: str
    """What happened, or why not: written for the person who asked."""
    transition: Transition | None = None
    """The transition made, if one was."""


@dataclass(frozen=True)
class ModeTick:
    """One tick of the machine: the mode whose tree ticked, and what followed."""

    mode: str
    snapshot: TickSnapshot
    transition: Transition | None = None
    """The transition made right after the tick (a condition or a timeout), if any."""
