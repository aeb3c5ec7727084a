"""The monitor's control seat: who may control, that only the connection holding the seat
does (nothing a page shows or says makes another page the holder), the secret that lets the
holder's page come back after a reload, and the hooks released when it does not come back."""

from __future__ import annotations

import asyncio
import json
from collections.abc import Iterator
from typing import Any

import pytest
from starlette.types import Message
from starlette.websockets import WebSocketDisconnect

from cyborg.monitor.hub import Hub
from cyborg.monitor.seat import ControlSeat, is_loopback
from cyborg.monitor.server import create_app
from tests.monitor.monitor_protocol import (
    campus_system,
    local_client,
    monitor_for,
    peer_from_header,
    receive_until,
)
from tests.running_system import System, wait_until


@pytest.fixture
def system() -> Iterator[System]:
    with campus_system() as running:
        yield running


@pytest.mark.parametrize(("host", "local"), [
    ("127.0.0.1", True), ("127.8.0.2", True), ("::1", True), ("::ffff:127.0.0.1", True),
    ("192.0.2.2", False), ("10.0.0.7", False), ("testclient", False), (None, False),
    ("::ffff:192.0.2.9", False)])
def test_loopback_detection(host: str | None, local: bool) -> None:
    assert is_loopback(host) is local


def test_one_controlling_client_a_token_for_others_and_a_grace_period() -> None:
    seat = ControlSeat(token="s3cret", grace=10.0)
    assert seat.may_control("127.0.0.1", None)
    assert not seat.may_control("192.0.2.9", None)
    assert not seat.may_control("192.0.2.9", "wrong")
    assert seat.may_control("192.0.2.9", "s3cret")
    assert not ControlSeat().may_control("192.0.2.9", ""), "no token configured: view only"
    assert seat.claim(1) == (True, None)
    assert seat.claim(2) == (False, None), "one controlling client at a time"
    seat.note_hook("/cyborg/bt", "n1", set_=True)
    assert seat.claim(2, force=True) == (True, 1)
    assert seat.holds(2) and not seat.holds(1)
    secret = seat.secret_for(2)
    assert secret and seat.secret_for(1) is None, "only the holder has the secret"
    seat.disconnected(2, now=100.0)
    assert not seat.holds(2)
    assert seat.claim(3) == (False, None), "the seat waits for its holder"
    assert not seat.resume(3, "guess") and not seat.resume(3, "")
    assert seat.expired(now=105.0) is None, "a reloading page keeps the seat"
    assert seat.resume(3, secret) and seat.holds(3), "the holder's page, reloaded"
    seat.disconnected(2, now=150.0)
    assert seat.holds(3), "the connection the holder left no longer counts"
    seat.disconnected(3, now=200.0)
    assert seat.expired(now=211.0) == {("/cyborg/bt", "n1")}, "its hooks are released"
    assert seat.holder is None
    assert not seat.resume(4, secret), "the secret of a freed seat is worth nothing"
    assert seat.claim(4) == (True, None)


def test_other_machines_watch_but_do_not_control_without_the_token(system: System) -> None:
    monitor = monitor_for(system, token="s3cret")
    try:
        with local_client(monitor.app, peer="192.0.2.9") as client:
            with client.websocket_connect("/ws") as socket:
                socket.send_json({"t": "hello", "key": "far"})
                assert receive_until(socket, "seat")["may_control"] is False
                socket.send_json({"t": "watch", "ns": "/cyborg/bt"})
                receive_until(socket, "tick")
                socket.send_json({"t": "enable", "on": False, "req": 1})
                assert "view only" in receive_until(socket, "result")["message"]
                socket.send_json({"t": "claim", "req": 2})
                assert "view only" in receive_until(socket, "error")["message"]
            assert system.runner.enabled
            with client.websocket_connect("/ws?token=s3cret") as socket:
                socket.send_json({"t": "hello", "key": "far-with-token"})
                assert receive_until(socket, "seat")["may_control"] is True
            with pytest.raises(WebSocketDisconnect) as refused, client.websocket_connect(
                    "/ws", headers={"origin": "http://evil.example"}) as socket:
                socket.receive_json()
            assert refused.value.code == 1008, "another site's page may not connect"
    finally:
        monitor.stop()


def test_the_seat_is_the_connection_that_took_it_not_a_key_another_page_can_show(
        system: System) -> None:
    monitor = monitor_for(system)
    try:
        with local_client(peer_from_header(monitor.app)) as client:
            with client.websocket_connect("/ws") as holder:
                holder.send_json({"t": "hello", "key": "page-holder"})
                receive_until(holder, "seat")
                holder.send_json({"t": "claim", "req": 1})
                assert receive_until(holder, "result")["ok"] is True
                mine = receive_until(holder, "seat")
                assert mine["control"] is True
                with client.websocket_connect("/ws", headers={"x-peer": "192.0.2.9"}) as spy:
                    spy.send_json({"t": "hello", "key": "spy"})
                    seen = receive_until(spy, "seat")
                    robots = receive_until(spy, "robots")
                    assert seen["may_control"] is False and seen["holder"] is not None
                    for shown in (seen["holder"], robots["seat"]):  # what it may present
                        spy.send_json({"t": "hello", "key": shown, "seat": shown})
                        spy.send_json({"t": "claim", "force": True})
                        assert "view only" in receive_until(spy, "error")["message"]
                    assert "secret" not in json.dumps([seen, robots, client.get(
                        "/api/robots").json()]), "the holder's secret went to another page"
                wait_until(lambda: len(monitor.hub.clients) == 1, 5, "the spy gone")
                holder.send_json({"t": "enable", "on": True, "ns": "/cyborg/bt", "req": 2})
                answer = receive_until(holder, "result")
                assert answer["ok"] is True, f"the holder lost the seat to a page that " \
                    f"showed its key and left: {answer['message']}"
                secret = mine["secret"]
            wait_until(lambda: not monitor.hub.clients, 5, "the holder gone")
            with client.websocket_connect("/ws") as other:
                other.send_json({"t": "hello", "seat": "guess"})
                assert receive_until(other, "seat")["control"] is False
                other.send_json({"t": "claim", "req": 3})
                assert receive_until(other, "result")["ok"] is False, "kept for its holder"
                with client.websocket_connect("/ws") as reloaded:
                    reloaded.send_json({"t": "hello", "seat": secret})
                    assert receive_until(reloaded, "seat")["control"] is True, \
                        "the holder's page comes back with its secret"
                    reloaded.send_json({"t": "enable", "on": True, "ns": "/cyborg/bt", "req": 4})
                    assert receive_until(reloaded, "result")["ok"] is True
    finally:
        monitor.stop()


def test_pages_connecting_at_the_same_moment_are_told_apart() -> None:
    hub = Hub(lambda namespace: pytest.fail("no tree is watched here"), list,
              default_namespace="/cyborg/bt", seat=ControlSeat())
    app = create_app(hub)
    accepting = asyncio.Barrier(2)
    answered = asyncio.Barrier(2)

    async def page(port: int) -> bool:
        incoming: asyncio.Queue[dict[str, Any]] = asyncio.Queue()
        incoming.put_nowait({"type": "websocket.connect"})
        incoming.put_nowait({"type": "websocket.receive",
                             "text": json.dumps({"t": "claim", "req": 1})})
        results: list[bool] = []

        async def send(message: Message) -> None:
            if message["type"] == "websocket.accept":
                await accepting.wait()  # both connections are being accepted now
            elif message["type"] == "websocket.send":
                answer = json.loads(message["text"])
                if answer["t"] == "result":
                    results.append(answer["ok"])
                    await answered.wait()
                    incoming.put_nowait({"type": "websocket.disconnect", "code": 1000})

        scope = {"type": "websocket", "path": "/ws", "raw_path": b"/ws", "root_path": "",
                 "scheme": "ws", "query_string": b"", "subprotocols": [],
                 "headers": [(b"host", b"127.0.0.1:8080")],
                 "client": ("127.0.0.1", port), "server": ("127.0.0.1", 8080),
                 "asgi": {"version": "3.0"}}
        await app(scope, incoming.get, send)
        return results == [True]

    async def both() -> tuple[bool, bool]:
        return await asyncio.wait_for(asyncio.gather(page(50001), page(50002)), 10)

    assert sorted(asyncio.run(both())) == [False, True], "one seat, two pages"


def test_the_hooks_of_a_holder_that_does_not_come_back_are_released(system: System) -> None:
    monitor = monitor_for(system)
    monitor.hub.seat.grace = 0.2
    hooks = system.runner.tree.hooks
    patrol, recharge = system.uid("Patrol"), system.uid("Recharge")
    try:
        wait_until(lambda: monitor.hub.sources["/cyborg/bt"].state is not None, 10,
                   "the structure")  # else a control names a node of no tree yet
        with local_client(monitor.app) as client:
            with client.websocket_connect("/ws") as holder:
                holder.send_json({"t": "watch", "ns": "/cyborg/bt"})
                commands: list[dict[str, Any]] = [
                    {"t": "claim"},
                    {"t": "control", "id": patrol, "action": "force", "status": "success"},
                    {"t": "control", "id": recharge, "action": "disable", "keep": True}]
                for request, command in enumerate(commands):
                    holder.send_json({**command, "req": request})
                    answer = receive_until(holder, "result")
                    assert answer["ok"] is True, answer["message"]
                assert hooks.get(patrol) is not None and hooks.get(recharge) is not None
            with client.websocket_connect("/ws") as other:
                other.send_json({"t": "hello"})
                wait_until(lambda: hooks.get(patrol) is None, 5, "the holder's hook released")
                assert hooks.get(recharge) is not None, "a hook set to be kept stays"
                for _ in range(20):
                    if receive_until(other, "seat")["holder"] is None:
                        break
                else:
                    raise AssertionError("the pages were not told that the seat is free")
                other.send_json({"t": "claim", "req": 9})
                assert receive_until(other, "result")["ok"] is True, "and anyone may take it"
    finally:
        monitor.stop()
