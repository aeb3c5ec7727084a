"""One tree runner, followed over the bus: its topics in, its control services out.

A :class:`TreeSource` subscribes to a runner's namespace (``/cyborg/bt`` by default; the topics
and services are those of :mod:`cyborg.interfaces.tree_runner`) and keeps a
:class:`~cyborg.monitor.tree_state.TreeState` up to date. It tells its listener what changed
(``"structure"``, ``"tick"``, ``"enabled"`` (or stopped), ``"hooks"``, ``"alive"``,
``"services"``) from the bus threads; the listener hands that to the web side. The runner's
``services`` message (the services on its composites) is kept as it came and read for the
page against the structure (:meth:`TreeSource.services_message`,
:mod:`cyborg.monitor.service_wire`).

It also follows the runner's liveliness: when the runner's process goes away the source says
``alive = False`` (the page shows it), and when a runner comes back its latched structure
arrives again and the page follows without a reload.

Control goes through the runner's services (``enable``, ``stop``, ``control``, ``step``,
``resume``, ``get_blackboard``) as blocking calls: call them from a worker thread.
"""

from __future__ import annotations

import json
import logging
import math
from collections.abc import Callable
from typing import Any

from cyborg.bt.outline import StructureError
from cyborg.bt.status import Status
from cyborg.bus import Node, Qos, Subscription, new_message
from cyborg.bus.wire import EntityKind
from cyborg.interfaces import tree_runner
from cyborg.interfaces.contract import Service
from cyborg.interfaces.tree_runner import HookAction, HookStatus
from cyborg.monitor.service_wire import page_services
from cyborg.monitor.tree_state import TreeState, status_name

log = logging.getLogger("cyborg.monitor")

Listener = Callable[[str, str], None]
"""``listener(namespace, what)``."""

HOOK_MODES = {int(action): action.label for action in HookAction
              if action is not HookAction.CLEAR}
CONTROL_ACTIONS = {action.label: int(action) for action in HookAction}
STATUSES = {Status(int(status)).label: int(status) for status in HookStatus}
"""The statuses a hook may give, by name."""
SERVICE_TIMEOUT = 5.0
BLACKBOARD_CHARACTERS = 2 << 20
"""Characters of a ``get_blackboard`` answer the monitor reads (the runner sends under 1 Mi)."""


def _refuse_constant(name: str) -> None:
    """``NaN`` and ``Infinity`` are not JSON: a browser's parser refuses the whole message."""
    raise ValueError(f"{name} is not a JSON value")


def _finite(text: str) -> float:
    """A JSON number as a float; one past a float's range (``1e999``) is refused, as above."""
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"{text[:20]} is past a float's range")
    return value


class ControlError(RuntimeError):
    """A control request the runner refused or did not answer; the message says why."""


class TreeSource:
    """Follows the tree runner under ``namespace``; see the module docstring."""

    def __init__(self, node: Node, namespace: str, listener: Listener) -> None:
        self.node, self.namespace = node, "/" + namespace.strip("/")
        self._listener = listener
        self.state: TreeState | None = None
        self.generation = 0
        """Bumped each time a structure arrives (a start, a restart or a reload)."""
        self.enabled: bool | None = None
        self.stopped: bool | None = None
        """Whether a STOP halted the tree until someone enables it (the runner's ``stopped``)."""
        self.hooks: list[dict[str, Any]] = []
        self.paused_at = ""
        self.alive = False
        self.problem = ""
        """Why the last structure could not be used, if it could not."""
        self.service_states: Any = None
        """The runner's last ``services`` message (cyborg_msgs/ServiceStates), as it came."""
        ns = self.namespace
        self._subscriptions: list[Subscription] = [
            tree_runner.STRUCTURE.subscription(node, self._on_structure, ns),
            tree_runner.ACTIVE_PATH.subscription(node, self._on_active, ns),
            tree_runner.ENABLED.subscription(node, self._on_enabled, ns),
            tree_runner.STOPPED.subscription(node, self._on_stopped, ns),
            tree_runner.HOOKS.subscription(node, self._on_hooks, ns),
            tree_runner.STATUS.subscription(node, self._on_status, ns, qos=Qos(depth=50)),
            tree_runner.SERVICE_STATES.subscription(node, self._on_services, ns),
        ]
        self._clients = {service.name: service.client(node, ns) for service in (
            tree_runner.ENABLE, tree_runner.STOP, tree_runner.CONTROL, tree_runner.STEP,
            tree_runner.RESUME, tree_runner.GET_BLACKBOARD)}
        self._remove_graph_listener = node.context.graph.on_change(self._check_alive)
        self._check_alive()

    # ------------------------------------------------------------------ topics in
    def _on_structure(self, message: Any) -> None:
        try:
            state = TreeState(message.tree)
        except StructureError as exc:
            self.problem = f"{tree_runner.STRUCTURE.full_name(self.namespace)}: {exc}"
            log.warning("%s", self.problem)
            return
        self.problem = ""
        self.state = state
        self.generation += 1
        self._tell("structure")

    def start_over(self) -> None:
        """Starts the tree's state over from its structure, as if the structure came again.

        For a played recording whose time jumped back to before anything of the tree ran: no
        status, no history of the other timeline.
        """
        state = self.state
        if state is not None:
            self.state = TreeState(state.text)
            self.generation += 1
            self._tell("structure")

    def _on_active(self, message: Any) -> None:
        state = self.state
        if state is not None:
            state.apply_active(list(message.ids))
            self._tell("tick")

    def _on_status(self, message: Any) -> None:
        state = self.state
        if state is None:
            return
        stamp = message.stamp
        state.apply_tick(int(message.tick), stamp.sec + stamp.nanosec * 1e-9,
                         float(message.duration), int(message.status), list(message.visited_ids),
                         message.visited_statuses, message.visited_durations,
                         list(message.active_ids))
        self._tell("tick")

    def _on_services(self, message: Any) -> None:
        self.service_states = message
        self._tell("services")

    def services_message(self) -> dict[str, Any] | None:
        """The page's ``services`` message for the tree as it is now; None without one.

        None before a structure or a ``services`` message came, and for a tree whose runner
        never published services.
        """
        state, message = self.state, self.service_states
        if state is None or message is None:
            return None
        return page_services(self.namespace, message, state)

    def _on_enabled(self, message: Any) -> None:
        self.enabled = bool(message.data)
        self._tell("enabled")

    def _on_stopped(self, message: Any) -> None:
        self.stopped = bool(message.data)
        self._tell("enabled")

    def _on_hooks(self, message: Any) -> None:
        self.hooks = [
            {"id": uid, "mode": HOOK_MODES.get(int(action), "?"),
             "status": status_name(int(status)),
             "owner": owner}
            for uid, action, status, owner in zip(message.node_ids, message.actions,
                                                  message.statuses, message.owners, strict=False)]
        self.paused_at = message.paused_at
        self._tell("hooks")

    def _check_alive(self) -> None:
        graph = self.node.context.graph
        alive = graph.count(tree_runner.STRUCTURE.full_name(self.namespace),
                            EntityKind.PUBLISHER) > 0
        if alive != self.alive:
            self.alive = alive
            if not alive:
                self.paused_at = ""
                self.stopped = None  # a runner that comes back publishes its own
                self.service_states = None  # a runner that comes back publishes its own
            self._tell("alive")

    def _tell(self, what: str) -> None:
        try:
            self._listener(self.namespace, what)
        except Exception:
            log.exception("monitor listener failed on %s %s", self.namespace, what)

    # ------------------------------------------------------------------ services out
    def _call(self, service: Service, **fields: Any) -> Any:
        client = self._clients[service.name]
        request = new_message(self.node.types, service.request_type, fields)
        try:
            return client.call(request, timeout=SERVICE_TIMEOUT)
        except Exception as exc:
            raise ControlError(f"{self.namespace}/{service.name}: {exc}") from exc

    def set_enabled(self, on: bool) -> str:
        """Enables or disables the tree, blocking up to :data:`SERVICE_TIMEOUT` s; the reply.

        Raises :class:`ControlError` when the runner refuses or does not answer.
        """
        response = self._call(tree_runner.ENABLE, data=on)
        if not response.success:
            raise ControlError(f"{self.namespace}/enable: {response.message}")
        self.enabled = on
        if on:
            self.stopped = False
        self._tell("enabled")
        return str(response.message)

    def stop(self) -> str:
        """Stops the tree (halted until enabled again), blocking up to :data:`SERVICE_TIMEOUT` s.

        Raises :class:`ControlError` when the runner does not answer.
        """
        response = self._call(tree_runner.STOP)
        self.enabled, self.stopped = False, True
        self._tell("enabled")
        return str(response.message)

    def control(self, node_id: str, action: str, status: str = "failure", *, once: bool = False,
                keep: bool = False) -> str:
        """Set or clear a hook; see ``cyborg_msgs/srv/ControlNode``."""
        if action not in CONTROL_ACTIONS:
            raise ControlError(f"unknown action {action!r}; expected one of "
                               f"{', '.join(CONTROL_ACTIONS)}")
        if status not in STATUSES:
            raise ControlError(f"unknown status {status!r}; expected one of "
                               f"{', '.join(STATUSES)}")
        response = self._call(tree_runner.CONTROL, node_id=node_id,
                              action=CONTROL_ACTIONS[action], status=STATUSES[status],
                              once=once, keep=keep)
        if not response.success:
            raise ControlError(str(response.message))
        return str(response.message)

    def trigger(self, service: str) -> str:
        """Call ``step`` or ``resume``."""
        triggers = {trigger.name: trigger for trigger in (tree_runner.STEP, tree_runner.RESUME)}
        if service not in triggers:
            raise ControlError(f"unknown trigger {service!r}")
        response = self._call(triggers[service])
        if not response.success:
            raise ControlError(f"{service}: {response.message}")
        return str(response.message)

    def blackboard(self) -> dict[str, Any]:
        """The runner's blackboard as JSON (``{"global", "tree", "node"}`` scopes).

        An answer past :data:`BLACKBOARD_CHARACTERS` is not read: one row says so instead
        (the runner's own view stays under 1 Mi characters; another may send anything).
        """
        response = self._call(tree_runner.GET_BLACKBOARD)
        text = response.json
        if len(text) > BLACKBOARD_CHARACTERS:
            return {"global": {"(not shown)": (
                f"(not shown: the blackboard is {len(text):,} characters, past the monitor's "
                f"{BLACKBOARD_CHARACTERS:,})")}}
        try:
            data = json.loads(text, parse_constant=_refuse_constant, parse_float=_finite)
        except (ValueError, RecursionError) as exc:
            raise ControlError(f"{self.namespace}/get_blackboard: not JSON "
                               f"({type(exc).__name__}: {str(exc)[:200]})") from None
        return data if isinstance(data, dict) else {"value": data}

    def describe(self) -> dict[str, Any]:
        """The short summary the page's robot list shows."""
        state = self.state
        return {"ns": self.namespace, "alive": self.alive, "enabled": self.enabled,
                "stopped": self.stopped, "title": state.structure.get("title", "") if state else "",
                "nodes": len(state) if state else 0, "tick": state.tick if state else 0,
                "problem": self.problem}

    def destroy(self) -> None:
        """Withdraws the subscriptions and service clients, and lets go of the tree.

        The bus node may keep its withdrawn entities, and through them this object, until the
        node itself is destroyed.
        """
        self._remove_graph_listener()
        for subscription in self._subscriptions:
            subscription.destroy()
        for client in self._clients.values():
            client.destroy()
        self._subscriptions, self._clients = [], {}
        self.state = None
        self._listener = _ignore


def _ignore(_namespace: str, _what: str) -> None:
    """The listener of a source that was destroyed."""
