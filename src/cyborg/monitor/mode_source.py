"""One tree runner's mode machine, followed over the bus for the page's Modes panel.

A runner given a mode file (docs/modes.md) serves :mod:`cyborg.interfaces.modes` beside its
tree. A :class:`ModeSource` subscribes to its latched ``<ns>/mode`` (cyborg_msgs/ModeState)
and to ``<ns>/mode/transitions`` (cyborg_msgs/ModeTransition), and keeps what the panel
draws: a :class:`ModeView` of the latest state and the last :data:`RECENT` transitions. Its
callbacks run on the monitor node's thread and only check, store and tell the listener.

**Nothing is drawn blank.** The machine arrives as JSON text (schema ``cyborg.modes.machine/1``)
and is checked here, as everything that comes over the bus: text that is not JSON, of another
schema, modes without names, transitions from or to modes the machine does not have. What can
be drawn is kept (a transition to nowhere is left out), and every fault becomes a line of
:attr:`ModeView.problems`, beside the problems the runner itself reports for a mode file that
failed to reload. The page shows those lines in the panel.

Forcing, requesting and holding go through the runner's ``mode/set`` service as blocking calls
(:meth:`ModeSource.set_mode`): call it from a worker thread. Liveness comes from the bus
graph: the machine is there while something publishes its state.
"""

from __future__ import annotations

import json
import logging
import math
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from cyborg.bus import Node, Qos, Subscription
from cyborg.bus.msgs.cyborg_msgs.msg import ModeState, ModeTransition
from cyborg.bus.msgs.cyborg_msgs.srv import SetMode_Request
from cyborg.bus.wire import EntityKind
from cyborg.interfaces import modes as contract
from cyborg.interfaces.modes import ModeAction

log = logging.getLogger("cyborg.monitor")

RECENT = 20
"""Transitions kept per machine for the pages (the newest last)."""
SERVICE_TIMEOUT = 5.0
"""Seconds a call to ``mode/set`` may take before it is given up."""
MACHINE_LIMIT = 256 * 1024
"""Characters of machine JSON read; a longer one is a problem, not a machine."""
MODES_LIMIT = 64
TRANSITIONS_LIMIT = 256
PROBLEMS_LIMIT = 50
TEXT_LIMIT = 200
"""Characters kept of a name, title, condition or reason."""
SCHEMA = "cyborg.modes.machine/1"

Listener = Callable[[], None]
"""Told (from the bus thread) that the state, the transitions or the liveness changed."""


class ModeError(RuntimeError):
    """The runner refused a mode request or did not answer; the message says which and why."""


@dataclass(frozen=True)
class ModeView:
    """One state of a runner's mode machine, as the panel draws it."""

    mode: str
    held: bool
    entered: float
    """Tree clock time at which the current mode was entered (s)."""
    count: int
    """Transitions the machine has made."""
    machine: dict[str, Any] | None
    """The checked machine: ``initial``, ``modes`` and ``transitions``; None if unreadable."""
    problems: tuple[str, ...]
    """The runner's problems with the mode file, then the monitor's with the machine."""

    def mode_names(self) -> list[str]:
        """The machine's modes, in the file's order (none when it could not be read)."""
        return [mode["name"] for mode in self.machine["modes"]] if self.machine else []

    def wire(self) -> dict[str, Any]:
        """The fields of the page's ``modes`` message."""
        return {"mode": self.mode, "held": self.held, "entered": round(self.entered, 3),
                "count": self.count, "machine": self.machine, "problems": list(self.problems)}


def clip(value: Any) -> str | None:
    """``value`` as text of at most :data:`TEXT_LIMIT` characters; None when it is none."""
    if value is None:
        return None
    text = value if isinstance(value, str) else json.dumps(value)
    return text if len(text) <= TEXT_LIMIT else text[:TEXT_LIMIT - 1] + "…"


def seconds(value: Any) -> float | None:
    """``value`` when it is a finite number of seconds, else None."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        return None
    return float(value)


def machine_of(text: str) -> tuple[dict[str, Any] | None, list[str]]:
    """The machine JSON ``text`` checked for drawing, and the problems found in it.

    The machine is None when nothing of it can be drawn (not JSON, another schema, no modes).
    """
    if len(text) > MACHINE_LIMIT:
        return None, [f"the machine is {len(text)} characters of JSON, over the "
                      f"{MACHINE_LIMIT} the monitor reads"]
    try:
        data = json.loads(text)
    except ValueError as exc:
        return None, [f"the machine is not JSON: {exc}"]
    if not isinstance(data, dict) or data.get("schema") != SCHEMA:
        schema = data.get("schema") if isinstance(data, dict) else None
        return None, [f"the machine's schema is {clip(schema)!r}, not {SCHEMA!r}"]
    problems: list[str] = []
    found = data.get("modes")
    modes: list[dict[str, Any]] = []
    for position, mode in enumerate(found if isinstance(found, list) else []):
        name = mode.get("name") if isinstance(mode, dict) else None
        if not isinstance(name, str) or not name or any(m["name"] == name for m in modes):
            problems.append(f"mode {position + 1} has no name of its own; left out")
            continue
        if len(modes) == MODES_LIMIT:
            problems.append(f"more than {MODES_LIMIT} modes; the rest are left out")
            break
        modes.append({"name": clip(name), "title": clip(mode.get("title")) or clip(name),
                      "tree": clip(mode.get("tree")), "description": clip(mode.get("description")),
                      "max_time": seconds(mode.get("max_time")), "then": clip(mode.get("then"))})
    if not modes:
        return None, [*problems, "the machine has no modes"]
    names = {mode["name"] for mode in modes}
    for mode in modes:
        if mode["then"] is not None and mode["then"] not in names:
            problems.append(f"mode {mode['name']!r}: then {mode['then']!r} is no mode; left out")
            mode["then"] = None
    transitions = _transitions(data.get("transitions"), names, problems)
    initial = data.get("initial")
    if not isinstance(initial, str) or initial not in names:
        problems.append(f"the initial mode {clip(initial)!r} is no mode of the machine")
        initial = None
    return {"initial": initial, "modes": modes, "transitions": transitions}, problems


def _transitions(found: Any, names: set[str], problems: list[str]) -> list[dict[str, Any]]:
    """The transitions of ``found`` that lead from and to modes in ``names``."""
    transitions: list[dict[str, Any]] = []
    for position, transition in enumerate(found if isinstance(found, list) else []):
        if len(transitions) == TRANSITIONS_LIMIT:
            problems.append(f"more than {TRANSITIONS_LIMIT} transitions; the rest are left out")
            break
        if not isinstance(transition, dict):
            problems.append(f"transition {position + 1} is not an object; left out")
            continue
        number = transition.get("number")
        if isinstance(number, bool) or not isinstance(number, int):
            number = position + 1
        label = f"transition {number}"
        sources, target = transition.get("from"), transition.get("to")
        if not isinstance(sources, list) or not sources \
                or not all(isinstance(s, str) and (s == "*" or s in names) for s in sources):
            problems.append(f"{label}: from {clip(sources)} names no mode of the machine; "
                            "left out")
            continue
        if not isinstance(target, str) or target not in names:
            problems.append(f"{label}: to {clip(target)!r} is no mode of the machine; left out")
            continue
        trigger = transition.get("trigger")
        transitions.append({
            "number": number, "from": sources,
            "to": target, "trigger": trigger if trigger in ("condition", "event", "request")
            else "request", "when": clip(transition.get("when")),
            "event": clip(transition.get("event")), "guard": clip(transition.get("guard")),
            "reason": clip(transition.get("reason"))})
    return transitions


def view_of(state: ModeState) -> ModeView:
    """``state`` checked for drawing: its machine read, every problem named."""
    machine, problems = machine_of(state.machine)
    mine = [clip(line) or "" for line in state.problems[:PROBLEMS_LIMIT]]
    if len(state.problems) > PROBLEMS_LIMIT:
        mine.append(f"… and {len(state.problems) - PROBLEMS_LIMIT} more problems")
    mode = clip(state.mode) or ""
    if machine is not None and mode not in {m["name"] for m in machine["modes"]}:
        problems.append(f"the current mode {mode!r} is no mode of the machine")
    entered = state.entered.sec + state.entered.nanosec * 1e-9
    return ModeView(mode=mode, held=bool(state.held), entered=entered,
                    count=int(state.transitions), machine=machine,
                    problems=tuple(mine + problems[:PROBLEMS_LIMIT]))


def transition_of(message: ModeTransition) -> dict[str, Any]:
    """One transition for the pages: from, to, reason, trigger, number and time (s)."""
    stamp = message.stamp
    return {"from": clip(message.from_mode), "to": clip(message.to_mode),
            "reason": clip(message.reason), "trigger": clip(message.trigger),
            "number": int(message.number), "time": round(stamp.sec + stamp.nanosec * 1e-9, 3)}


class ModeSource:
    """Follows the mode machine of the runner under ``namespace``; see the module docstring."""

    def __init__(self, node: Node, namespace: str, listener: Listener) -> None:
        self.node, self.namespace = node, "/" + namespace.strip("/")
        self._listener = listener
        self.view: ModeView | None = None
        """The latest state; None before the first."""
        self.recent: deque[dict[str, Any]] = deque(maxlen=RECENT)
        """The last transitions heard, the newest last."""
        self.alive = False
        self._lock = threading.Lock()
        ns = self.namespace
        self._subscriptions: list[Subscription[Any]] = [
            contract.STATE.subscription(node, self._on_state, ns),
            contract.TRANSITIONS.subscription(node, self._on_transition, ns,
                                              qos=Qos(depth=contract.TRANSITION_DEPTH))]
        self._set = contract.SET_MODE.client(node, ns)
        self._remove_graph_listener = node.context.graph.on_change(self._check_alive)
        self._check_alive()

    def _on_state(self, message: ModeState) -> None:
        view = view_of(message)
        with self._lock:
            self.view = view
        self._tell()

    def _on_transition(self, message: ModeTransition) -> None:
        with self._lock:
            self.recent.append(transition_of(message))
        self._tell()

    def wire(self) -> dict[str, Any] | None:
        """The ``modes`` field of the page's message: the state and the recent transitions."""
        with self._lock:
            view, recent = self.view, list(self.recent)
        if view is None:
            return None
        return {**view.wire(), "recent": recent}

    def _check_alive(self) -> None:
        alive = self.node.context.graph.count(contract.STATE.full_name(self.namespace),
                                              EntityKind.PUBLISHER) > 0
        if alive != self.alive:
            self.alive = alive
            self._tell()

    def _tell(self) -> None:
        try:
            self._listener()
        except Exception:
            log.exception("monitor listener failed on the modes of %s", self.namespace)

    def set_mode(self, action: ModeAction, mode: str = "", reason: str = "") -> str:
        """Asks the runner to request, force, hold or release; its answer.

        :class:`ModeError` when it refuses or does not answer within :data:`SERVICE_TIMEOUT`.
        """
        name = contract.SET_MODE.full_name(self.namespace)
        try:
            response = self._set.call(SetMode_Request(action=int(action), mode=mode,
                                                      reason=reason), timeout=SERVICE_TIMEOUT)
        except Exception as exc:
            raise ModeError(f"{name}: {exc}") from exc
        if not response.success:
            raise ModeError(f"{name}: {response.message}")
        return str(response.message)

    def destroy(self) -> None:
        """Withdraws the subscriptions and the service client; the listener hears no more."""
        self._remove_graph_listener()
        self._listener = _ignore
        for subscription in self._subscriptions:
            subscription.destroy()
        self._set.destroy()


def _ignore() -> None:
    """The listener of a source that was destroyed."""
