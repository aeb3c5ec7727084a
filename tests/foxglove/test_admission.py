"""Who may connect: loopback by default, a token for the network, the monitor's Host rules."""

from __future__ import annotations

import pytest
from websockets.exceptions import InvalidStatus

from cyborg.access import HostPolicy
from cyborg.bus import BusConfig, Context, Node
from cyborg.foxglove import FoxgloveError, FoxgloveServer
from cyborg.foxglove.admission import Admission, Handshake, parse_handshake
from tests.foxglove.conftest import Served

TOKEN = "s3cret-ø"


def handshake(host: str = "127.0.0.1:8765", target: str = "/", **headers: str) -> Handshake:
    return Handshake("GET", target, {"host": host, **headers})


@pytest.fixture
def rules() -> Admission:
    return Admission(HostPolicy(own_names={"robot"}, server="Foxglove server"), TOKEN)


def test_a_handshake_is_read_with_its_headers() -> None:
    parsed = parse_handshake(b"GET /?token=abc HTTP/1.1\r\nHost: robot:8765\r\n"
                             b"Sec-WebSocket-Protocol: foxglove.sdk.v1\r\n")
    assert (parsed.method, parsed.target) == ("GET", "/?token=abc")
    assert parsed.headers["sec-websocket-protocol"] == "foxglove.sdk.v1"
    assert parsed.token == "abc"
    with pytest.raises(ValueError, match="not an HTTP request line"):
        parse_handshake(b"hello there\r\n")
    with pytest.raises(ValueError, match="not a header line"):
        parse_handshake(b"GET / HTTP/1.1\r\nno colon here\r\n")


def test_the_token_comes_from_the_address_or_a_bearer_header() -> None:
    assert handshake(target="/?token=t1").token == "t1"
    assert handshake(authorization="Bearer t2").token == "t2"
    assert handshake(authorization="Basic t3").token is None
    assert handshake().token is None


def test_this_machine_may_connect_without_the_token(rules: Admission) -> None:
    assert rules.refusal(handshake(), peer_loopback=True) is None
    assert rules.refusal(handshake(origin="https://app.foxglove.dev"), peer_loopback=True) is None


def test_other_machines_need_the_token(rules: Admission) -> None:
    refusal = rules.refusal(handshake("robot:8765"), peer_loopback=False)
    assert refusal is not None and "need the token" in refusal
    assert rules.refusal(handshake("robot:8765", target="/?token=wrong"),
                         peer_loopback=False) == "403: wrong token\n"
    assert rules.refusal(handshake("robot:8765", target="/?token=s3cret-%C3%B8"),
                         peer_loopback=False) is None


def test_a_foreign_web_page_may_not_read_the_bus_from_this_machine(rules: Admission) -> None:
    refusal = rules.refusal(handshake(origin="https://evil.example"), peer_loopback=True)
    assert refusal is not None and "--allow-origin" in refusal
    allowed = Admission(HostPolicy(own_names={"robot"}), None, ["https://tools.example/"])
    assert allowed.refusal(handshake(origin="https://tools.example"), peer_loopback=True) is None


def test_an_unknown_host_name_is_refused_as_dns_rebinding(rules: Admission) -> None:
    refusal = rules.refusal(handshake("rebind.attacker.example:8765", target="/?token=" + TOKEN),
                            peer_loopback=True)
    assert refusal is not None and "--allow-host rebind.attacker.example" in refusal
    assert "Foxglove server" in refusal


def test_listening_beyond_loopback_without_a_token_is_refused(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("CYBORG_MONITOR_TOKEN", raising=False)
    with Context(BusConfig.isolated()) as context:
        server = FoxgloveServer(Node("foxglove", context=context), host="0.0.0.0", port=0)
        with pytest.raises(FoxgloveError, match=r"--host 0\.0\.0\.0 .* set a token"):
            server.start()
        with_token = FoxgloveServer(Node("foxglove2", context=context), host="0.0.0.0",
                                    port=0, token=TOKEN)
        with_token.start()
        try:
            assert with_token.exposure() is not None
        finally:
            with_token.stop()


def test_a_refused_handshake_gets_403_and_a_reason(served: Served) -> None:
    with pytest.raises(InvalidStatus, match="403"):
        served.client(headers={"Origin": "https://evil.example"})
    assert served.server.gate is not None and served.server.gate.refused == 1
