"""A tree runner's mode machine on the bus: its state, its transitions, its service, its events.

When the runner runs a mode file (docs/modes.md) it serves :mod:`cyborg.interfaces.modes`
through a :class:`ModeEndpoints`: the latched ``mode`` state (published when the mode or the
hold changes, after a reload, and after a reload that failed, with the file's problems), each
transition on ``mode/transitions``, the ``mode/set``
service (request, force, hold, release) and the ``mode/events`` topic, whose every message
fires the event it names.

The service and the events are answered on a thread of their own: a request waits for the tick
in progress to end (the machine never switches inside a tick), and must not wait behind the
node's other callbacks, nor they behind it.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Callable, Sequence

from cyborg.bus import Node
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import ModeState, ModeTransition
from cyborg.bus.msgs.cyborg_msgs.srv import SetMode, SetMode_Request, SetMode_Response
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.interfaces import modes
from cyborg.interfaces.modes import ModeAction
from cyborg.modes import Decision, ModeMachine, Transition

log = logging.getLogger("cyborg.runner")


class ModeEndpoints:
    """Serves the mode machine that ``current()`` returns (the runner's, after any reload)."""

    def __init__(self, node: Node, current: Callable[[], ModeMachine]) -> None:
        self._current = current
        self.problems: tuple[str, ...] = ()
        """Why the latest reload of the mode file failed; empty after a good load."""
        self._state = modes.STATE.publisher(node)
        self._transitions = modes.TRANSITIONS.publisher(node)
        thread = node.callback_thread("mode")
        modes.SET_MODE.server(node, self._on_set, callbacks=thread)
        self._events = modes.EVENTS.subscription(node, self._on_event)
        node.callbacks.route(self._events, thread)

    def publish_state(self) -> None:
        """Publishes the machine's current mode, hold and shape (latched)."""
        machine = self._current()
        self._state.publish(ModeState(
            entered=stamp(machine.entered or 0.0), mode=machine.mode, held=machine.held,
            transitions=machine.transition_count,
            machine=json.dumps(machine.spec.to_json(), separators=(",", ":")),
            problems=list(self.problems)))

    def loaded(self) -> None:
        """A mode file loaded (at start or a reload): its state, with no problems."""
        self.problems = ()
        self.publish_state()

    def load_failed(self, problems: Sequence[str]) -> None:
        """A reload failed: the state again, naming the file's ``problems`` (one a line).

        The machine that loaded before keeps running; monitors show the problems beside it.
        """
        self.problems = tuple(problems)
        self.publish_state()

    def publish_transition(self, transition: Transition) -> None:
        """Publishes one transition, then the state it led to."""
        self._transitions.publish(ModeTransition(
            stamp=stamp(transition.time), from_mode=transition.source,
            to_mode=transition.target, reason=transition.reason,
            trigger=transition.trigger.value, number=transition.number or 0))
        self.publish_state()

    # ------------------------------------------------------------------ requests
    def _on_set(self, request: SetMode_Request) -> SetMode_Response:
        machine = self._current()
        try:
            action = ModeAction(request.action)
        except ValueError:
            return self._answer(machine, Decision(False, f"unknown action {request.action}; "
                                                  "REQUEST=0, FORCE=1, HOLD=2, RELEASE=3"))
        if action is ModeAction.REQUEST:
            decision = machine.request(request.mode, request.reason)
        elif action is ModeAction.FORCE:
            decision = machine.force(request.mode, request.reason)
        else:
            machine.hold(action is ModeAction.HOLD)
            verb = "held" if action is ModeAction.HOLD else "released"
            decision = Decision(True, f"mode {machine.mode!r} {verb}")
            self.publish_state()
        return self._answer(machine, decision)

    @staticmethod
    def _answer(machine: ModeMachine, decision: Decision) -> SetMode_Response:
        return SetMode.Response(success=decision.accepted, message=decision.message,
                                mode=machine.mode)

    def _on_event(self, message: String) -> None:
        decision = self._current().fire_event(message.data)
        log.info("mode event %r: %s", message.data, decision.message)


def stamp(seconds: float) -> Time:
    """Seconds of the tree clock as a ``builtin_interfaces/Time``."""
    whole = int(seconds // 1)
    return Time(sec=whole, nanosec=min(int((seconds - whole) * 1e9), 999_999_999))
