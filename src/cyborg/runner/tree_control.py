"""Per-node control of a running tree over the bus, for monitors and tools.

Services under the tree runner's namespace, as :mod:`cyborg.interfaces.tree_runner` names them:

=================  ============================  ===============================================
name               type                          what
=================  ============================  ===============================================
``control``        cyborg_msgs/ControlNode       disable a subtree, force a result, set or clear
                                                 a breakpoint on one node
``resume``         std_srvs/Trigger              let a tick waiting at a breakpoint go on
``step``           std_srvs/Trigger              go on to the next node about to tick, and stop
``get_blackboard`` cyborg_msgs/GetBlackboard     the blackboard's three scopes as JSON
``hooks``          cyborg_msgs/BehaviorTreeHooks latched topic: the hooks set, where a tick waits
=================  ============================  ===============================================

**Hooks follow their client.** Each hook remembers the service client that set it (by the GID in
the request, which names the client's liveliness token). When that client leaves the bus — the
monitor is closed, its machine drops off — its hooks are released within the liveliness timeout
(about 2 s), so a forgotten breakpoint or a disabled branch never outlives whoever set it.
A request with ``keep`` set survives its client; so does one from a client the runner cannot
see on the bus (reported in the reply).

The services run on the thread the runner gives (``callbacks``), not on its node's thread, so
a reload or anything else the node does never delays them.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import Any

import numpy as np

from cyborg.bt import FAILURE, RUNNING, SUCCESS, Hook, HookError, HookMode, Tree
from cyborg.bus import Node
from cyborg.bus.executor import CallbackThread
from cyborg.bus.msgs.cyborg_msgs.msg import BehaviorTreeHooks
from cyborg.bus.msgs.cyborg_msgs.srv import (
    ControlNode,
    ControlNode_Request,
    ControlNode_Response,
    GetBlackboard,
    GetBlackboard_Request,
    GetBlackboard_Response,
)
from cyborg.bus.msgs.std_srvs.srv import Trigger, Trigger_Request, Trigger_Response
from cyborg.bus.services import Responder
from cyborg.bus.wire import EntityKind, gid
from cyborg.interfaces import tree_runner
from cyborg.interfaces.tree_runner import HookAction, HookStatus
from cyborg.runner.blackboard_view import blackboard_json

log = logging.getLogger("cyborg.runner")

ACTIONS = {int(HookAction.DISABLE): HookMode.DISABLE, int(HookAction.FORCE): HookMode.FORCE,
           int(HookAction.BREAKPOINT): HookMode.BREAKPOINT}
CODES = {mode: code for code, mode in ACTIONS.items()}
STATUSES = {int(HookStatus.SUCCESS): SUCCESS, int(HookStatus.FAILURE): FAILURE,
            int(HookStatus.RUNNING): RUNNING}
_ACTION_CHOICES = ", ".join(f"{int(code)} {code.label}" for code in HookAction)
_STATUS_NAMES = [f"{int(code)} {code.name.lower()}" for code in HookStatus]
_STATUS_CHOICES = f"{', '.join(_STATUS_NAMES[:-1])} or {_STATUS_NAMES[-1]}"
"""The codes, for error messages: ``0 clear, 1 disable, ...``, ``1 success, ... or 3 running``."""
SEE_CALLER = 1.0
"""Seconds to wait for a caller's liveliness token to show up in the graph."""


class TreeControl:
    """The control services of one tree runner; ``current()`` is the tree being ticked."""

    def __init__(self, node: Node, current: Callable[[], Tree], *,
                 callbacks: CallbackThread | None = None) -> None:
        self.node, self.current = node, current
        self.graph = node.context.graph
        self._owners: dict[str, str] = {}  # owner (client GID hex) -> its node's name
        self._lock = threading.Lock()
        self._hooks = tree_runner.HOOKS.publisher(node)
        tree_runner.CONTROL.server(node, self._on_control, deferred=True, callbacks=callbacks)
        tree_runner.RESUME.server(node, self._on_resume, callbacks=callbacks)
        tree_runner.STEP.server(node, self._on_step, callbacks=callbacks)
        tree_runner.GET_BLACKBOARD.server(node, self._on_blackboard, callbacks=callbacks)
        current().hooks.listeners.append(self.publish)
        self._stop_watching = self.graph.on_change(self._release_departed)
        self.publish()

    # ------------------------------------------------------------------ hooks topic
    def publish(self) -> None:
        """Publish the hooks set on the current tree, and where a tick waits, on ``hooks``.

        Called again by the tree's hooks whenever they change (on whichever thread changed
        them).
        """
        hooks = self.current().hooks
        entries = hooks.hooks()
        self._hooks.publish(BehaviorTreeHooks(
            node_ids=[hook.node for hook in entries],
            actions=np.array([CODES[hook.mode] for hook in entries], np.uint8),
            statuses=np.array([int(hook.status) for hook in entries], np.uint8),
            owners=[self._owners.get(hook.owner, "") for hook in entries],
            paused_at=hooks.paused_at or ""))

    def tree_replaced(self, old: Tree, new: Tree) -> None:
        """Follow the runner to a reloaded tree (its hooks were carried over already)."""
        if self.publish in old.hooks.listeners:
            old.hooks.listeners.remove(self.publish)
        new.hooks.listeners.append(self.publish)
        self.publish()

    # ------------------------------------------------------------------ owners
    def _caller(self, caller: bytes) -> str | None:
        """The node name of the client with GID ``caller``, if it is on the bus."""
        found: list[str] = []

        def look(graph: Any) -> bool:
            for entity in graph.entities([EntityKind.SERVICE_CLIENT]):
                if gid(entity.key) == caller:
                    found.append(entity.node_name)
                    return True
            return False
        self.graph.wait_for(look, SEE_CALLER)
        return found[0] if found else None

    def _release_departed(self) -> None:
        with self._lock:
            if not self._owners:
                return
            present = {gid(entity.key).hex()
                       for entity in self.graph.entities([EntityKind.SERVICE_CLIENT])}
            gone = [owner for owner in self._owners if owner not in present]
            for owner in gone:
                name = self._owners.pop(owner)
                released = self.current().hooks.clear_owner(owner)
                if released:
                    log.info("released %d hook(s) of %s, which left the bus", len(released),
                             name)

    # ------------------------------------------------------------------ services
    def _on_control(self, request: ControlNode_Request,
                    responder: Responder[ControlNode_Response]) -> None:
        response = ControlNode.Response
        hooks = self.current().hooks
        uid, action = str(request.node_id), int(request.action)
        note = ""
        try:
            if action == HookAction.CLEAR:
                cleared = hooks.clear(uid)
                responder.reply(response(success=True, message="cleared" if cleared else
                                         f"node {uid} had no hook"))
                return
            mode = ACTIONS.get(action)
            if mode is None:
                raise HookError(f"unknown action {action}: use {_ACTION_CHOICES}")
            status = SUCCESS
            if mode is not HookMode.BREAKPOINT:
                if int(request.status) not in STATUSES:
                    raise HookError(f"status {request.status} is not {_STATUS_CHOICES}")
                status = STATUSES[int(request.status)]
            owner = ""
            if not request.keep:
                name = self._caller(responder.caller_gid)
                if name is None:
                    note = "; kept: the caller is not visible on the bus"
                else:
                    owner = responder.caller_gid.hex()
                    with self._lock:
                        self._owners[owner] = name
            hooks.set(Hook(uid, mode, status, once=bool(request.once), owner=owner))
        except HookError as exc:
            responder.reply(response(success=False, message=str(exc)))
            return
        responder.reply(response(success=True, message=f"{mode.value} set on {uid}{note}"))

    @staticmethod
    def _trigger(success: bool, message: str) -> Trigger_Response:
        return Trigger.Response(success=success, message=message)

    def _on_resume(self, _request: Trigger_Request) -> Trigger_Response:
        resumed = self.current().hooks.resume()
        return self._trigger(resumed, "resumed" if resumed else "no tick is waiting")

    def _on_step(self, _request: Trigger_Request) -> Trigger_Response:
        stepped = self.current().hooks.step()
        return self._trigger(stepped, "stepping" if stepped else "no tick is waiting")

    def _on_blackboard(self, _request: GetBlackboard_Request) -> GetBlackboard_Response:
        return GetBlackboard.Response(json=blackboard_json(self.current().blackboard.as_dict()))

    def destroy(self) -> None:
        """Stop following clients in the graph; the services go with the runner's node."""
        self._stop_watching()

