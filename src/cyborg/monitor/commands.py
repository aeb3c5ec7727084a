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
map          on                                          show the map (true) or not: the
                                                         robots' state (robot_hub.py)
go           ns, goal                                    send the robot ``ns`` to a named goal
go_pose      ns, pose: [x, y] or [x, y, θ]               send it to a pose
home         ns                                          send it home
dock         ns                                          dock it
undock       ns                                          undock it
set_pose     ns, pose: [x, y] or [x, y, θ]               relocalise it
stop         ns                                          stop it and halt its tree until
                                                         resumed (needs no seat)
drive        ns, vx, wz                                  drive it by hand (10 Hz while held)
tour         ns, points                                  drive it through the points in order
player_pause paused                                      pause (true) or resume (false) the
                                                         played recording (player_link.py)
player_seek  position: s from the start, 0 to duration   go to that time of the recording
player_step  —                                           play its next message, stay paused
mode_force   ns, mode, reason                            enter the mode at once (mode_link.py)
mode_request ns, mode, reason                            ask for the mode as the file allows
mode_hold    ns, held                                    hold the current mode (true) or
                                                         release it (false)
ping         —                                           answered with pong (for latency)
===========  ==========================================  =====================================

``enable``, ``control``, ``step`` and ``resume`` need the control seat; so do the robot
commands (``go`` … ``tour``) but ``stop``, which any page that may control sends, and the
player's (``player_pause``, ``player_seek``, ``player_step``) and the mode machine's
(``mode_force``, ``mode_request``, ``mode_hold``). The robot
commands, their answers (``result``, ``robot_result``, ``tour``, ``manual_pause``) and why a
manual goal pauses the tree are in :mod:`cyborg.monitor.robot_commands`. While a recording
plays (the monitor follows a ``cyborg play``), every command that would act on a robot, a tree
or a mode machine is refused (:data:`REPLAY_REFUSAL`), as the page disables them; a ``stop``
and an ``enable`` with ``on: false`` still go out.

A message the monitor cannot read or will not carry out is answered with a *located* error::

    {"t": "error", "n": 7, "req": 3, "command": "watch", "field": "ns", "pos": null,
     "message": "message 7 (watch), field ns: '/**' is not a namespace: ..."}

``n`` counts the messages this connection sent (from 1); ``req`` and ``command`` are the
message's own (null when it could not be read), ``field`` the field at fault, ``pos`` the
character where the JSON went wrong. Refused control commands are ``result`` messages with
``ok: false`` (and the same ``n``). No message, however malformed, ends the connection or
reaches the log as a traceback.
"""

from __future__ import annotations

import logging
from collections.abc import Awaitable, Callable
from typing import Any

from cyborg.monitor.client import Client
from cyborg.monitor.hub import Hub
from cyborg.monitor.limits import MessageError, check_namespace, decode
from cyborg.monitor.mode_link import MODE_COMMANDS, ModeError
from cyborg.monitor.off_loop import ShutdownError, in_thread
from cyborg.monitor.player_link import PLAYER_COMMANDS, PlayerError
from cyborg.monitor.refusal import RefusalError
from cyborg.monitor.robot_commands import ROBOT_COMMANDS
from cyborg.monitor.source import ControlError

log = logging.getLogger("cyborg.monitor")

CONTROLS = ("enable", "control", "step", "resume")
SECRET_LIMIT = 64
REPLAY_REFUSAL = ("refused while a recording plays (cyborg play): it would act on no robot; a "
                  "stop or a disable still goes out")
"""Why a command that acts is refused while the monitor follows a player (as the page says)."""


async def receive(hub: Hub, client: Client, text: str | None) -> None:
    """Reads one message from ``client``, carries it out, and answers any fault as an error.

    ``text`` is None for a binary frame. The error names the message and field at fault (see
    the module docstring). Runs on the server's event loop.
    """
    client.received += 1
    command: Any = None
    try:
        if text is None:
            raise MessageError("binary frames are not read: send JSON text")
        if not client.bucket.take():
            raise MessageError("too many messages: slow down (this one was not read)")
        command = decode(text)
        await handle(hub, client, command)
    except (RefusalError, ControlError) as exc:  # MessageError and LimitError are refusals
        client.send(located_error(client, command, exc))
    except ShutdownError as exc:  # the monitor is stopping: no worker takes the call
        client.send(located_error(client, command, exc))
    except Exception as exc:  # a bug: logged with its traceback, the connection goes on
        log.exception("monitor: message %d of connection %d failed", client.received,
                      client.number)
        client.send(located_error(client, command, RuntimeError(
            f"the monitor failed on this message ({type(exc).__name__}); see its log")))


def located_error(client: Client, command: Any, exc: Exception) -> dict[str, Any]:
    """The ``error`` message for ``exc``, raised by message number ``client.received``."""
    known = command if isinstance(command, dict) else {}
    kind = known.get("t") if isinstance(known.get("t"), str) else None
    field = getattr(exc, "field", None)
    pos = getattr(exc, "pos", None)
    where = f"message {client.received}" + (f" ({kind[:40]})" if kind else "")
    where += f", field {field}" if field else ""
    where += f", character {pos}" if pos is not None else ""
    return {"t": "error", "n": client.received, "req": known.get("req"), "command": kind,
            "field": field, "pos": pos, "message": f"{where}: {exc}"}


async def handle(hub: Hub, client: Client, command: Any) -> None:
    """Carry out one command from ``client`` and queue what it answers."""
    if not isinstance(command, dict) or not isinstance(command.get("t"), str):
        raise RefusalError('a command is a JSON object with a string "t"', "t")
    kind = command["t"]
    if hub.player.source is not None and _acts(kind, command):
        client.send({"t": "result", "n": client.received, "req": command.get("req"),
                     "command": kind, "ok": False, "field": None,
                     "message": f"{kind}: {REPLAY_REFUSAL}"})
    elif kind in CONTROLS:
        await _tree_control(hub, client, kind, command)
    elif kind in ROBOT_COMMANDS:
        await _robot_command(hub, client, kind, command)
    elif kind in PLAYER_COMMANDS:
        await _link_command(client, kind, command, hub.player.handle(client, kind, command),
                            PlayerError)
    elif kind in MODE_COMMANDS:
        await _link_command(client, kind, command, hub.modes.handle(client, kind, command),
                            ModeError)
    elif kind in PAGE_COMMANDS:
        PAGE_COMMANDS[kind](hub, client, command)
    else:
        raise RefusalError(f"unknown command {kind[:40]!r}", "t")


async def _tree_control(hub: Hub, client: Client, kind: str, command: dict[str, Any]) -> None:
    """``enable``, ``control``, ``step``, ``resume``: answered with ``result``."""
    answer = {"t": "result", "n": client.received, "req": command.get("req")}
    try:
        message = await _control(hub, client, kind, command)
    except (RefusalError, ControlError) as exc:
        client.send({**answer, "ok": False, "message": str(exc)})
    else:
        client.send({**answer, "ok": True, "message": message})


def _hello(hub: Hub, client: Client, command: dict[str, Any]) -> None:
    """The page's first message: its seat back (by secret) or the seat's state, the robots."""
    secret = command.get("seat")
    if (client.may_control and isinstance(secret, str) and len(secret) <= SECRET_LIMIT
            and hub.seat.resume(client.number, secret)):
        hub.announce_seat()  # the page's old connection, if still open, hears it lost
    else:
        client.send(hub.seat_message(client))
    client.send(hub.robots())
    hub.robot_commands.resend(client)
    hub.player.resend(client)


def _watch(hub: Hub, client: Client, command: dict[str, Any]) -> None:
    """Follow the tree under ``ns`` (default: the monitor's) on this page."""
    try:
        hub.watch(client, command.get("ns") or hub.default_namespace)
    except (ValueError, RefusalError) as exc:  # a bad name, or one namespace too many
        raise RefusalError(str(exc), "ns") from None


def _history(hub: Hub, client: Client, _command: dict[str, Any]) -> None:
    """The watched tree's kept ticks."""
    source = hub.sources.get(client.watching or "")
    state = source.state if source else None
    client.send({"t": "history", "ns": client.watching, "v": state.version if state else None,
                 "ticks": state.history_json() if state else []})


def _claim(hub: Hub, client: Client, command: dict[str, Any]) -> None:
    """Take the control seat (``force``: from the page that holds it)."""
    hub.seat.require(client.number, client.may_control, seat=False)
    held = hub.seat.holds(client.number)
    granted, _taken_from = hub.seat.claim(client.number, force=bool(command.get("force")))
    client.send({"t": "result", "n": client.received, "req": command.get("req"), "ok": granted,
                 "message": "you have control" if granted else
                 "another page has control; take it over to control from here"})
    if granted and not held:  # every page hears of a change, and only of one
        hub.announce_seat()


def _release(hub: Hub, client: Client, _command: dict[str, Any]) -> None:
    """Give the control seat up."""
    if hub.seat.release(client.number):
        hub.announce_seat()


def _map(hub: Hub, client: Client, command: dict[str, Any]) -> None:
    """The page shows the map (``on``): it gets the robots' state, or no longer."""
    if not isinstance(command.get("on"), bool):
        raise RefusalError("map: on must be true or false", "on")
    hub.robot_hub.view(client, command["on"])


PAGE_COMMANDS: dict[str, Callable[[Hub, Client, dict[str, Any]], None]] = {
    "hello": _hello, "watch": _watch, "refresh": lambda hub, client, _command: hub.resync(client),
    "history": _history, "claim": _claim, "release": _release, "map": _map,
    "ping": lambda _hub, client, command: client.send({"t": "pong", "req": command.get("req")}),
}
"""The page's own commands (its session, the seat, what it shows), each answered at once."""


def _acts(kind: str, command: dict[str, Any]) -> bool:
    """Whether ``command`` would act on a robot or a tree (a stop or a disable never counts)."""
    if kind == "stop" or (kind == "enable" and command.get("on") is False):
        return False
    return kind in CONTROLS or kind in ROBOT_COMMANDS or kind in MODE_COMMANDS


async def _robot_command(hub: Hub, client: Client, kind: str, command: dict[str, Any]) -> None:
    """A robot command (:mod:`cyborg.monitor.robot_commands`), answered with ``result``."""
    answer = {"t": "result", "n": client.received, "req": command.get("req"), "command": kind}
    try:
        done = await hub.robot_commands.handle(client, kind, command)
    except RefusalError as exc:
        client.send({**answer, "ok": False, "field": exc.field,
                     "message": located_error(client, command, exc)["message"]})
        return
    if done is not None:
        client.send({**answer, "ok": True, **done})


async def _link_command(client: Client, kind: str, command: dict[str, Any],
                        handled: Awaitable[str], failed: type[Exception]) -> None:
    """A command to a link (the player's, a mode machine's), answered with ``result``.

    ``handled`` is the link's handling of it; a refusal names the field at fault, ``failed`` is
    the link's error when the bus side refused or did not answer.
    """
    answer = {"t": "result", "n": client.received, "req": command.get("req"), "command": kind}
    try:
        message = await handled
    except RefusalError as exc:
        client.send({**answer, "ok": False, "field": exc.field,
                     "message": located_error(client, command, exc)["message"]})
    except failed as exc:
        client.send({**answer, "ok": False, "field": None, "message": str(exc)})
    else:
        client.send({**answer, "ok": True, "message": message})


async def _control(hub: Hub, client: Client, kind: str, command: dict[str, Any]) -> str:
    hub.seat.require(client.number, client.may_control)
    namespace = command.get("ns") or client.watching
    try:
        namespace = check_namespace(namespace)
    except ValueError as exc:
        raise RefusalError(f"ns: {exc}", "ns") from None
    source = hub.sources.get(namespace)
    if source is None:
        raise RefusalError(f"no tree is watched under {namespace!r}", "ns")
    if kind == "enable":
        on = command.get("on")
        if not isinstance(on, bool):
            raise RefusalError("enable: on must be true or false", "on")
        return await in_thread(source.set_enabled, on)
    if kind in ("step", "resume"):
        return await in_thread(source.trigger, kind)
    node_id, action = command.get("id"), command.get("action")
    if not isinstance(node_id, str) or not isinstance(action, str):
        raise RefusalError("control: id and action must be strings",
                           "id" if not isinstance(node_id, str) else "action")
    state = source.state
    if state is None or node_id not in state.index_of:
        raise RefusalError(f"control: no node {node_id[:80]!r} in the tree under "
                           f"{source.namespace}", "id")
    status = command.get("status") or "failure"
    once, keep = bool(command.get("once")), bool(command.get("keep"))
    message = await in_thread(source.control, node_id, action, str(status),
                                      once=once, keep=keep)
    hub.seat.note_hook(source.namespace, node_id, set_=action != "clear" and not keep)
    return message
