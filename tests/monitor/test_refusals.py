"""One refusal error (cyborg.monitor.refusal.RefusalError) for what a page sent that the monitor
will not carry out: answered located, never logged; and a fault of the monitor's own, even one
raising ValueError, is not passed off as a refusal: it is logged with its traceback and the page
told the monitor failed."""

from __future__ import annotations

import logging
from typing import Any

import pytest

from cyborg.monitor.hub import LimitError
from cyborg.monitor.limits import MessageError
from cyborg.monitor.refusal import RefusalError
from cyborg.monitor.server import create_app
from tests.monitor.monitor_protocol import bare_hub, local_client, receive_until


def test_the_specific_refusals_are_refusals() -> None:
    assert issubclass(MessageError, RefusalError) and issubclass(LimitError, RefusalError)
    assert not issubclass(RefusalError, ValueError), "a bug's ValueError is no refusal"
    refused = MessageError("not JSON", pos=3)
    assert (refused.field, refused.pos, str(refused)) == (None, 3, "not JSON")


def test_a_refusal_is_answered_naming_the_field_and_not_logged(
        caplog: pytest.LogCaptureFixture) -> None:
    hub = bare_hub()
    with caplog.at_level(logging.DEBUG), local_client(create_app(hub)) as client, \
            client.websocket_connect("/ws") as socket:
        socket.send_json({"t": "map", "on": "yes"})
        error = receive_until(socket, "error")
    assert error["field"] == "on" and error["message"] == \
        "message 1 (map), field on: map: on must be true or false"
    assert not [record for record in caplog.records if record.exc_info]


def test_a_value_error_from_a_fault_is_logged_and_answered_as_a_failure(
        caplog: pytest.LogCaptureFixture, monkeypatch: pytest.MonkeyPatch) -> None:
    hub = bare_hub()

    def broken(*_args: Any) -> Any:
        raise ValueError("a fault in the monitor")
    monkeypatch.setattr(hub, "robots", broken)
    with caplog.at_level(logging.DEBUG), local_client(create_app(hub)) as client, \
            client.websocket_connect("/ws") as socket:
        socket.send_json({"t": "hello"})
        error = receive_until(socket, "error")
    assert "the monitor failed on this message (ValueError)" in error["message"], error
    assert "a fault in the monitor" not in error["message"]
    (logged,) = [record for record in caplog.records if record.exc_info]
    assert "message 1 of connection" in logged.getMessage()
