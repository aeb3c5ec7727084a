"""Who may reach the monitor and who may control through it (docs/security.md, "Web monitor"):
the Host allow-list that defeats DNS rebinding, the page's own origin (scheme, host and port),
the token (never a bus parameter, from a file or the environment, any Unicode), and the
loopback default with what listening wider prints. Bus-free where possible (fake trees)."""

from __future__ import annotations

import logging
import os
import socket
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from starlette.testclient import WebSocketDenialResponse
from starlette.websockets import WebSocketDisconnect

from cyborg.app.cli import build_parser
from cyborg.app.monitor_commands import monitor_description
from cyborg.app.up import up_description
from cyborg.bus import BusConfig, Context, Node
from cyborg.bus.component import NodeSpec
from cyborg.monitor import Monitor
from cyborg.monitor.access import HostPolicy, TokenError, own_origin, read_token
from cyborg.monitor.component import RunningMonitor
from cyborg.monitor.component import start as start_monitor
from cyborg.monitor.monitor import _lan_address
from cyborg.monitor.seat import ControlSeat
from cyborg.monitor.server import create_app
from tests.monitor.monitor_protocol import bare_hub, local_client, next_json, receive_until

REBOUND = "http://rebind.attacker.example:8080"


@pytest.fixture
def context() -> Iterator[Context]:
    with Context(BusConfig.isolated()) as opened:
        yield opened


# ---------------------------------------------------------------------------------- 1 hosts
@pytest.mark.parametrize(("host", "allowed"), [
    ("localhost:8080", True), ("LOCALHOST", True), ("app.localhost:8080", True),
    ("127.0.0.1:8080", True), ("[::1]:8080", True), ("10.0.0.7:8080", True),
    ("robot:8080", True), ("robot.local", True), ("robot.campus.example:8080", True),
    ("a.lab.example", True), ("lab.example", True),
    ("rebind.attacker.example:8080", False), ("localhost.attacker.example", False),
    ("127.0.0.1.attacker.example", False), ("robotx:8080", False), ("xlab.example", False),
    ("", False), (None, False), ("robot:8080/x", False), ("robot :8080", False),
    ("robot:99999", False), ("user@robot", False), ("[::1", False)])
def test_the_host_header_is_checked_against_an_allow_list(host: str | None,
                                                          allowed: bool) -> None:
    policy = HostPolicy(["robot.campus.example", ".lab.example"],
                        own_names=["robot", "robot.local"])
    assert policy.allows(host) is allowed
    assert HostPolicy(["*"]).allows("anything.example:1"), "'*' turns the check off"


def test_a_page_from_a_rebound_name_gets_403_over_http_and_websocket() -> None:
    """rebind.attacker.example resolves to 127.0.0.1: the browser sends its own name as Host,
    and its Origin matches that Host, so only the Host allow-list tells it apart."""
    app = create_app(bare_hub(), hosts=HostPolicy(own_names=[]))
    with local_client(app, base_url=REBOUND) as client:
        for response in (client.get("/"), client.get("/api/robots"), client.get("/stats"),
                         client.post("/api/export", json={"ns": "/cyborg/bt",
                                                          "format": "dot"})):
            assert response.status_code == 403
            assert "--allow-host rebind.attacker.example" in response.text
        with pytest.raises(WebSocketDenialResponse) as refused, \
                client.websocket_connect("/ws", headers={"origin": REBOUND}):
            pass
        assert refused.value.status_code == 403
    allowed = create_app(bare_hub(), hosts=HostPolicy(["rebind.attacker.example"]))
    with local_client(allowed, base_url=REBOUND) as client:
        assert client.get("/api/robots").status_code == 200, "a name the user allowed"
    with local_client(app) as client:
        assert client.get("/").status_code == 200


@pytest.mark.parametrize(("origin", "own"), [
    ("http://127.0.0.1:8080", True), ("HTTP://127.0.0.1:8080", True),
    ("https://127.0.0.1:8080", False), ("http://127.0.0.1:8081", False),
    ("http://127.0.0.1", False), ("http://localhost:8080", False), ("null", False),
    ("file://", False), ("http://127.0.0.1:8080:1", False)])
def test_the_page_origin_is_scheme_host_and_port(origin: str, own: bool) -> None:
    assert own_origin(origin, "ws", "127.0.0.1:8080") is own
    assert own_origin("https://robot", "wss", "robot:443")
    assert not own_origin("https://robot", "ws", "robot:443")


def test_another_origin_may_not_connect_and_controls_only_with_the_token() -> None:
    """A page of another origin on this machine (a loopback peer) is no longer trusted for
    being on loopback: without the token it cannot connect, with it it may control."""
    hub = bare_hub(token="s3cret")
    with local_client(create_app(hub)) as client:
        for origin in ("https://127.0.0.1:8080", "http://localhost:3000", "null"):
            with pytest.raises(WebSocketDisconnect) as refused, \
                    client.websocket_connect("/ws", headers={"origin": origin}) as socket:
                next_json(socket)
            assert refused.value.code == 1008, origin


def test_another_origin_with_the_token_may_control() -> None:
    hub = bare_hub(token="s3cret")
    with local_client(create_app(hub)) as client:
        with pytest.raises(WebSocketDisconnect), client.websocket_connect(
                "/ws?token=wrong", headers={"origin": "http://localhost:3000"}) as refused:
            next_json(refused)
        with client.websocket_connect("/ws?token=s3cret",
                                      headers={"origin": "http://localhost:3000"}) as socket:
            socket.send_json({"t": "hello"})
            assert receive_until(socket, "seat")["may_control"] is True
        with client.websocket_connect("/ws", headers={"origin": "http://127.0.0.1:8080"}) \
                as socket:
            socket.send_json({"t": "hello"})
            assert receive_until(socket, "seat")["may_control"] is True, "the page itself"


def test_exports_are_refused_to_other_origins() -> None:
    """A cross-site form may POST (it cannot read the answer), but each export runs Graphviz."""
    with local_client(create_app(bare_hub())) as client:
        body = {"ns": "/cyborg/bt", "format": "dot"}
        refused = client.post("/api/export", json=body, headers={"origin": "http://evil.example"})
        assert refused.status_code == 403
        assert client.post("/api/export", json=body,
                           headers={"origin": "http://127.0.0.1:8080"}).status_code == 200
        assert client.post("/api/export", json=body).status_code == 200, "a script"


# ---------------------------------------------------------------------------------- 3 token
def test_a_non_ascii_token_works() -> None:
    seat = ControlSeat(token="ø-s3cret")
    assert seat.may_control("192.0.2.9", "ø-s3cret")
    assert not seat.may_control("192.0.2.9", "o-s3cret")
    assert not seat.may_control("192.0.2.9", "\ud800"), "a lone surrogate is just wrong"
    assert not seat.resume(1, "\udcff")
    with local_client(create_app(bare_hub(token="ø")), peer="192.0.2.9") as client, \
            client.websocket_connect("/ws?token=%C3%B8") as socket:
        socket.send_json({"t": "hello"})
        assert receive_until(socket, "seat")["may_control"] is True


def test_the_token_is_never_a_bus_parameter(context: Context) -> None:
    running = start_monitor(context, NodeSpec("monitor", "monitor", "/cyborg",
                                              {"token": "s3cret", "port": 0}))
    try:
        node = running.monitor.node
        assert "token" not in node.parameters.names()
        values = [repr(node.parameters[name]) for name in node.parameters.names()]
        assert not any("s3cret" in value for value in values), values
        assert running.monitor.hub.seat.may_control("192.0.2.9", "s3cret")
    finally:
        running.stop()


def test_the_token_comes_from_a_file_or_the_environment(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    secret = tmp_path / "token"
    secret.write_text("ø-s3cret\n")
    secret.chmod(0o600)
    assert read_token(token_file=secret, environ={}) == "ø-s3cret"
    assert read_token(token="given", token_file=secret, environ={}) == "given"
    assert read_token(environ={"CYBORG_MONITOR_TOKEN": "from-env"}) == "from-env"
    assert read_token(environ={}) is None
    with pytest.raises(TokenError, match="missing"):
        read_token(token_file=tmp_path / "missing", environ={})
    (tmp_path / "empty").write_text("\n")
    with pytest.raises(TokenError, match="empty"):
        read_token(token_file=tmp_path / "empty", environ={})
    secret.chmod(0o644)
    with caplog.at_level(logging.WARNING, "cyborg.monitor"):
        read_token(token_file=secret, environ={})
    assert "other users can read" in caplog.text


def test_a_token_file_that_is_a_fifo_or_a_folder_is_refused_at_once(tmp_path: Path) -> None:
    """Opening a FIFO with no writer waited for one: cyborg monitor and foxglove never started."""
    fifo = tmp_path / "token.fifo"
    os.mkfifo(fifo)
    said: list[str] = []

    def read(path: Path) -> None:
        with pytest.raises(TokenError) as refused:
            read_token(token_file=path, environ={})
        said.append(str(refused.value))

    for path in (fifo, tmp_path):
        reader = threading.Thread(target=read, args=(path,), daemon=True)
        reader.start()
        reader.join(30)
        assert not reader.is_alive(), f"reading {path} still waits"
    assert said == [f"token file {fifo}: not a regular file",
                    f"token file {tmp_path}: Is a directory"]


def test_cyborg_monitor_and_up_options(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    parser = build_parser()
    plain = parser.parse_args(["monitor"])
    assert plain.host == "127.0.0.1", "loopback unless asked"
    parameters = monitor_description(plain).nodes[0].parameters
    assert parameters["host"] == "127.0.0.1" and "token" not in parameters
    secret = tmp_path / "token"
    secret.write_text("s3cret")
    wide = parser.parse_args(["monitor", "--host", "0.0.0.0", "--token-file", str(secret),
                              "--allow-host", "robot.campus.example", "--allow-host", "r2"])
    parameters = monitor_description(wide).nodes[0].parameters
    assert parameters["token_file"] == str(secret) and "token" not in parameters
    assert parameters["allow_hosts"] == ["robot.campus.example", "r2"]
    assert capsys.readouterr().err == ""
    given = parser.parse_args(["monitor", "--token", "s3cret"])
    assert monitor_description(given).nodes[0].parameters["token"] == "s3cret", "still works"
    assert "--token shows in `ps`" in capsys.readouterr().err
    up = parser.parse_args(["up"])
    monitor = next(node for node in up_description(up).nodes if node.kind == "monitor")
    assert monitor.parameters["host"] == "127.0.0.1"
    up = parser.parse_args(["up", "--monitor-host", "0.0.0.0", "--allow-host", "robot.local",
                            "--token-file", str(secret)])
    monitor = next(node for node in up_description(up).nodes if node.kind == "monitor")
    assert (monitor.parameters["host"], monitor.parameters["allow_hosts"],
            monitor.parameters["token_file"]) == ("0.0.0.0", ["robot.local"], str(secret))


# ---------------------------------------------------------------------------------- 2 bind
def test_the_monitor_listens_on_loopback_unless_told_and_then_says_so(
        context: Context, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("CYBORG_MONITOR_TOKEN", raising=False)
    running = start_monitor(context, NodeSpec("monitor", "monitor", "/cyborg", {"port": 0}))
    try:
        assert running.monitor.host == "127.0.0.1"
        assert "(this machine only)" in running.describe()
        assert "listening" not in running.describe()
        address = _lan_address()
        if address is not None:  # the port is not open on this machine's network address
            with socket.socket() as far, pytest.raises(ConnectionRefusedError):
                far.settimeout(2)
                far.connect((address, running.monitor.port))
    finally:
        running.stop()
    wide = start_monitor(context, NodeSpec("monitor", "monitor2", "/cyborg",
                                           {"port": 0, "host": "0.0.0.0"}))
    try:
        text = wide.describe()
        assert text.splitlines()[0].startswith("monitor      /cyborg/monitor2: open http")
        assert f"listening on 0.0.0.0:{wide.monitor.port} (every interface)" in text
        assert "no token: other machines may only watch" in text
    finally:
        wide.stop()
    monkeypatch.setenv("CYBORG_MONITOR_TOKEN", "s3cret")
    with_token = RunningMonitor(Monitor(Node("monitor3", "/cyborg", context=context),
                                        host="0.0.0.0", port=0))
    with_token.monitor.start()
    try:
        assert "a token is set: other machines control with it" in with_token.describe()
    finally:
        with_token.stop()


def test_environment_token_is_read_by_the_monitor(monkeypatch: pytest.MonkeyPatch,
                                                  context: Context) -> None:
    monkeypatch.setenv("CYBORG_MONITOR_TOKEN", "from-env")
    running = start_monitor(context, NodeSpec("monitor", "monitor", "/cyborg", {"port": 0}))
    try:
        assert running.monitor.hub.seat.may_control("192.0.2.9", "from-env")
    finally:
        running.stop()
    assert os.environ["CYBORG_MONITOR_TOKEN"] == "from-env"
