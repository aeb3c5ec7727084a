"""What a browser may ask of the monitor over its WebSocket, and the answers.

Every command is a JSON object with a type ``t`` and an optional request number ``req``; the
answer to a command that does something is ``{"t": "result", "req", "ok", "message"}``.

===========  ==========================================  =====================================
``t``        fields                                      what
===========  ==========================================  =====================================
hello        seat                                        first message; ``seat``: the seat's
                                                         secret, to take back the seat this
                                                         page held before a reload
watch        ns                                          follow the tree under ``ns``
refresh      —                                           structure and snapshot again
history      —                                           the recent ticks of the watched tree
claim        force                                       take the control seat
release      —                                           give it up
enable       on                                          run (true) or pause (false) the tree
control      id, action, status, once, keep              hook a node (see ControlNode.srv)
step         —                                           at a breakpoint: on to the next node
resume       —                                           at a breakpoint: go on
ping         —                                           answered with pong (for latency)
===========  ==========================================  =====================================

``enable``, ``control``, ``step`` and ``resume`` need the control seat.
"""

from __future__ import annotations

import asyncio
from typing import Any

from cyborg.monitor.client import Client
from cyborg.monitor.hub import Hub
from cyborg.monitor.source import ControlError

CONTROLS = ("enable", "control", "step", "resume")
SECRET_LIMIT = 64


class CommandError(ValueError):
    """A command that is malformed or not allowed; the message says why."""


async def handle(hub: Hub, client: Client, command: Any) -> None:
    """Carry out one command from ``client`` and queue what it answers."""
    if not isinstance(command, dict) or not isinstance(command.get("t"), str):
        raise CommandError('a command is a JSON object with a string "t"')
    kind, request = command["t"], command.get("req")
    if kind in CONTROLS:
        try:
            message = await _control(hub, client, kind, command)
        except (CommandError, ControlError) as exc:
            client.send({"t": "result", "req": request, "ok": False, "message": str(exc)})
        else:
            client.send({"t": "result", "req": request, "ok": True, "message": message})
        return
    if kind == "hello":
        secret = command.get("seat")
        if (client.may_control and isinstance(secret, str) and len(secret) <= SECRET_LIMIT
                and hub.seat.resume(client.number, secret)):
            hub.announce_seat()  # the page's old connection, if still open, hears it lost
        else:
            client.send(hub.seat_message(client))
        client.send(hub.robots())
    elif kind == "watch":
        namespace = command.get("ns") or hub.default_namespace
        if not isinstance(namespace, str) or not namespace.startswith("/"):
            raise CommandError(f"watch: ns must be a namespace such as /cyborg/bt, "
                               f"not {namespace!r}")
        client.watching = "/" + namespace.strip("/")
        client.send({"t": "watching", "ns": client.watching})
        hub.send_tree(client, client.watching)
        hub.broadcast(hub.robots())
    elif kind == "refresh":
        hub.resync(client)
    elif kind == "history":
        source = hub.sources.get(client.watching or "")
        state = source.state if source else None
        client.send({"t": "history", "ns": client.watching,
                     "v": state.version if state else None,
                     "ticks": state.history_json() if state else []})
    elif kind == "claim":
        if not client.may_control:
            raise CommandError("view only: control is accepted from this machine, or with "
                               "the monitor's token")
        granted, _taken_from = hub.seat.claim(client.number, force=bool(command.get("force")))
        client.send({"t": "result", "req": request, "ok": granted,
                     "message": "you have control" if granted else
                     "another page has control; take it over to control from here"})
        if granted:
            hub.announce_seat()
    elif kind == "release":
        hub.seat.release(client.number)
        hub.announce_seat()
    elif kind == "ping":
        client.send({"t": "pong", "req": request})
    else:
        raise CommandError(f"unknown command {kind!r}")


async def _control(hub: Hub, client: Client, kind: str, command: dict[str, Any]) -> str:
    if not client.may_control:
        raise CommandError("view only: control is accepted from this machine, or with the "
                           "monitor's token")
    if not hub.seat.holds(client.number):
        raise CommandError("another page has control (or none was taken): take control first")
    namespace = command.get("ns") or client.watching
    source = hub.sources.get(namespace or "")
    if source is None:
        raise CommandError(f"no tree is watched under {namespace!r}")
    if kind == "enable":
        on = command.get("on")
        if not isinstance(on, bool):
            raise CommandError("enable: on must be true or false")
        return await asyncio.to_thread(source.set_enabled, on)
    if kind in ("step", "resume"):
        return await asyncio.to_thread(source.trigger, kind)
    node_id, action = command.get("id"), command.get("action")
    if not isinstance(node_id, str) or not isinstance(action, str):
        raise CommandError("control: id and action must be strings")
    state = source.state
    if state is None or node_id not in state.index_of:
        raise CommandError(f"control: no node {node_id!r} in the tree under {source.namespace}")
    status = command.get("status") or "failure"
    once, keep = bool(command.get("once")), bool(command.get("keep"))
    message = await asyncio.to_thread(source.control, node_id, action, str(status),
                                      once=once, keep=keep)
    hub.seat.note_hook(source.namespace, node_id, set_=action != "clear" and not keep)
    return message
