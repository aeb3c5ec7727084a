"""A mode machine as its file declares it, checked and resolved, before any tree is built.

:func:`cyborg.modes.mode_file.read_mode_file` produces a :class:`MachineSpec`; the engine
(:class:`cyborg.modes.machine.ModeMachine`) runs one. Every name in it has been checked: each
mode's tree exists in its file, every ``from``, ``to`` and ``then`` names a mode, every mode can
be reached from the initial one, and every expression parsed.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from cyborg.bt.editor_format import ProjectSpec
from cyborg.modes.conditions import Condition

ANY = "*"
"""The ``from`` of a transition that may leave every mode (but the one it leads to)."""
SCHEMA = "cyborg.modes.machine/1"
"""The name of :meth:`MachineSpec.to_json`'s form, for monitors that draw the machine."""


@dataclass(frozen=True)
class ModeSpec:
    """One mode: a name and the tree that runs while the machine is in it."""

    name: str
    tree: str
    """The tree's id in :attr:`project` (resolved from the id, title or file the file gave)."""
    project: ProjectSpec = field(repr=False, compare=False)
    """The behavior3editor file the tree is read from."""
    min_dwell: float
    """Seconds on the tree clock before a condition, event or request may leave the mode."""
    max_time: float | None = None
    """Seconds after which the mode is left for :attr:`then`; None: no limit."""
    then: str | None = None
    description: str = ""
    line: int | None = None
    """The line of the mode's table in the mode file."""


@dataclass(frozen=True)
class TransitionSpec:
    """One way from mode to mode; exactly one trigger (``when``, ``event`` or ``on_request``)."""

    number: int
    """Its place among the file's transitions, from 1: lower numbers are tried first."""
    sources: tuple[str, ...]
    """The modes it may leave; ``("*",)`` for every mode but :attr:`target`."""
    target: str
    when: Condition | None = None
    """Fires after a tick in which this condition on the global blackboard is true."""
    event: str | None = None
    """Fires when this event is published (:meth:`ModeMachine.fire_event`)."""
    on_request: bool = False
    """May be taken by a request (:meth:`ModeMachine.request`), the ``cyborg bt mode`` call."""
    guard: Condition | None = None
    """Must also be true, whatever the trigger."""
    reason: str = ""
    """What the transition log says when it fires (default: the trigger itself)."""
    line: int | None = None

    def leaves(self, mode: str) -> bool:
        """Whether the transition may leave ``mode``."""
        if self.sources == (ANY,):
            return mode != self.target
        return mode in self.sources

    @property
    def label(self) -> str:
        """``transition 3 (normal → demo)``: how messages name it."""
        sources = ", ".join(self.sources)
        return f"transition {self.number} ({sources} → {self.target})"

    @property
    def trigger(self) -> str:
        """The trigger in words: ``when battery.percent < 20``, ``event help``, ``request``."""
        if self.when is not None:
            return f"when {self.when.source}"
        if self.event is not None:
            return f"event {self.event}"
        return "request"


@dataclass(frozen=True)
class MachineSpec:
    """The whole machine: its modes, the initial one, its transitions in priority order."""

    source: str
    """The mode file."""
    modes: dict[str, ModeSpec]
    initial: str
    transitions: tuple[TransitionSpec, ...]
    min_dwell: float = 0.0
    """The default dwell of modes that set none."""

    def to_json(self) -> dict[str, Any]:
        """The machine as JSON, for monitors: modes with their trees, transitions in order.

        ``{"schema": "cyborg.modes.machine/1", "source", "initial", "min_dwell", "modes":
        [{"name", "tree", "title", "description", "min_dwell", "max_time", "then"}, ...],
        "transitions": [{"number", "from": [...], "to", "trigger": "condition" | "event" |
        "request", "when", "event", "guard", "reason"}, ...]}``; absent values are null.
        """
        modes = []
        for mode in self.modes.values():
            titles = [tree.title for tree in mode.project.trees if tree.id == mode.tree]
            modes.append({"name": mode.name, "tree": mode.tree,
                          "title": titles[0] if titles else mode.tree,
                          "description": mode.description, "min_dwell": mode.min_dwell,
                          "max_time": mode.max_time, "then": mode.then})
        transitions = [{
            "number": t.number, "from": list(t.sources), "to": t.target,
            "trigger": "condition" if t.when else "event" if t.event else "request",
            "when": t.when.source if t.when else None, "event": t.event,
            "guard": t.guard.source if t.guard else None, "reason": t.reason or None}
            for t in self.transitions]
        return {"schema": SCHEMA, "source": self.source, "initial": self.initial,
                "min_dwell": self.min_dwell, "modes": modes, "transitions": transitions}

    def reachable(self) -> set[str]:
        """The modes a path of transitions or timeouts leads to from :attr:`initial`."""
        return reachable(self.initial, self.modes, self.transitions)


def reachable(initial: str, modes: dict[str, ModeSpec],
              transitions: tuple[TransitionSpec, ...]) -> set[str]:
    """Modes reached from ``initial`` by any transition (condition, event, request) or ``then``.

    A force reaches any mode, so it is no path: a mode only an operator can enter is a mistake
    in the file, most often a transition forgotten. Time linear in the modes and transitions:
    each transition is looked at once per mode it names in ``from``, and a ``"*"`` one once.
    """
    leading: dict[str, list[str]] = {}
    from_any: list[str] = []
    for transition in transitions:
        if transition.sources == (ANY,):
            from_any.append(transition.target)
        else:
            for source in transition.sources:
                leading.setdefault(source, []).append(transition.target)
    seen, frontier = {initial}, [initial]
    # "*" leaves every mode but its target, and the initial mode is one: its targets other
    # than the initial mode are reached from it, and the initial mode is reached already.
    following_any = from_any
    while frontier:
        mode = frontier.pop()
        following = leading.get(mode, []) + following_any
        following_any = []
        then = modes[mode].then if mode in modes else None
        if then is not None:
            following.append(then)
        for target in following:
            if target not in seen and target in modes:
                seen.add(target)
                frontier.append(target)
    return seen
