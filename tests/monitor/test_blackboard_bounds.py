"""The monitor reads a runner's blackboard within bounds: an answer of tens of megabytes becomes
one row saying so (it was forwarded whole to pages, past their queue's bound), JSON nested too
deep a located error, and no page is sent a message past the size any message may have."""

from __future__ import annotations

import json
import logging
from collections.abc import Iterator

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cyborg.bus import BusConfig, Context, Node
from cyborg.bus.msgs.cyborg_msgs.srv import GetBlackboard_Response
from cyborg.interfaces import tree_runner
from cyborg.monitor.client import MESSAGE_CHARACTERS, Client
from cyborg.monitor.source import BLACKBOARD_CHARACTERS, ControlError, TreeSource
from tests.running_system import wait_until


@pytest.fixture
def bus() -> Iterator[Context]:
    context = Context(BusConfig.isolated())
    yield context
    context.close()


def source_answered(bus: Context, answer: str) -> TreeSource:
    """A monitor's source of a runner whose ``get_blackboard`` answers ``answer``."""
    runner = Node("tree_runner", tree_runner.NAMESPACE, context=bus)
    tree_runner.GET_BLACKBOARD.server(
        runner, lambda _request: GetBlackboard_Response(json=answer))
    source = TreeSource(Node("monitor", "/cyborg", context=bus), tree_runner.NAMESPACE,
                        lambda _namespace, _what: None)
    client = source._clients[tree_runner.GET_BLACKBOARD.name]
    wait_until(lambda: client.wait_for_service(0.1), timeout=10, what="get_blackboard")
    return source


def test_a_huge_blackboard_is_one_row_saying_so(bus: Context) -> None:
    huge = json.dumps({"global": {"x": "y" * (33 << 20)}})  # 33.5 MB, as a runner once sent
    data = source_answered(bus, huge).blackboard()
    (row,) = data["global"].values()
    assert row.startswith("(not shown: the blackboard is 34,603,0")
    assert f"{BLACKBOARD_CHARACTERS:,}" in row
    assert len(json.dumps(data)) < 1000


def test_a_blackboard_nested_too_deep_is_a_located_error(bus: Context) -> None:
    deep = "[" * 100_000 + "]" * 100_000  # under the size bound, past the parser's recursion
    with pytest.raises(ControlError, match="/cyborg/bt/get_blackboard: not JSON"):
        source_answered(bus, deep).blackboard()


def test_no_message_past_the_bound_reaches_a_page(caplog: pytest.LogCaptureFixture) -> None:
    client = Client(1, None, may_control=False)  # type: ignore[arg-type]
    with caplog.at_level(logging.WARNING, "cyborg.monitor"):
        client.send('{"t":"blackboard","data":"' + "x" * MESSAGE_CHARACTERS + '"}')
    assert client.queue.empty() and client.dropped == 1
    assert "was not sent" in caplog.text and '{"t":"blackboard"' in caplog.text
    client.send({"t": "tick"})
    assert client.queue.qsize() == 1, "smaller messages still go"



JSON_PIECES = st.sampled_from(['[', ']', '{', '}', '"k":', '1', '1e999', '-0', 'NaN', 'null',
                               '"\\ud800"', ',', '"x"', ' ', '[[[[[[[[', '9' * 5000])


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(pieces=st.lists(JSON_PIECES, max_size=60), repeat=st.integers(1, 3000))
def test_any_blackboard_answer_is_data_or_a_located_error(pieces: list[str], repeat: int) -> None:
    """Whatever text a runner answers, the monitor gets a dict of scopes or a ControlError."""
    text = "".join(pieces) * repeat
    source = TreeSource.__new__(TreeSource)
    source.namespace = "/fuzzed"
    source._call = lambda _service, **_fields: GetBlackboard_Response(json=text)  # type: ignore[method-assign]
    try:
        data = source.blackboard()
    except ControlError as exc:
        assert str(exc).startswith("/fuzzed/get_blackboard: not JSON"), exc
    else:
        assert isinstance(data, dict)
        json.dumps(data, allow_nan=False)  # what the hub encodes: strict JSON for the pages
