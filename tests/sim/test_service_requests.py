"""Wrong service requests: a one-line error for the caller, a located log line on the server.

The attacks of issue 19 (item 12) first: requests with the wrong types are stopped on the
client, requests the handler cannot use (NaN poses) are refused before it runs, a handler that
raises or answers badly gives one line with the service's name, never its traceback; then
hypothesis sends typed and garbage requests to the live navigation and simulator services and
checks that each gets an answer or one line, and that the services keep answering.
"""

from __future__ import annotations

import logging
import math
import os
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import zenoh
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from cyborg.bus import BusConfig, Context, Node, ServiceError, ServiceTimeoutError, new_message
from cyborg.bus.services import RequestError
from cyborg.nav.arnl_map import parse_map
from cyborg.sim.loop import SimulationLoop
from cyborg.sim.node import NO_PATH, SimulatorNode
from cyborg.sim.simulator import Simulator
from tests.small_maps import room_map, write

ROOM = room_map(['Goal 2000 3000 0 "" ICON "left"', 'GoalWithHeading 8000 3000 90 "" ICON "right"'])
TRIGGER = "std_srvs/srv/Trigger"


@pytest.fixture(scope="module")
def robot() -> Iterator[tuple[Node, Simulator]]:
    with Context(BusConfig.isolated()) as context:
        sim = Simulator(parse_map(ROOM, "room.map"), start="left")
        loop = SimulationLoop(sim, speed=1)
        SimulatorNode(Node("arnl", "/cyborg", context=context), loop)
        loop.start()
        yield Node("client", "/cyborg", context=context), sim
        loop.stop()


def call(node: Node, name: str, service: str, request: Any, timeout: float = 10.0) -> Any:
    return node.create_client(name, service).call(request, timeout=timeout)


def request(node: Node, service: str, **fields: Any) -> Any:
    return new_message(node.types, f"{service}_Request", fields)


def one_line(error: BaseException, service: str) -> str:
    text = str(error)
    assert "\n" not in text and "Traceback" not in text, text
    assert service in text, text
    return text


def still_answers(node: Node) -> None:
    goals = call(node, "nav/get_available_goals", "cyborg_msgs/srv/AvailableGoals",
                 request(node, "cyborg_msgs/srv/AvailableGoals")).goals
    assert [goal.name for goal in goals] == ["left", "right"]
    plan = call(node, "make_plan", "cyborg_msgs/srv/MakePlan", request(
        node, "cyborg_msgs/srv/MakePlan", goal={"x": 8.0, "y": 3.0}, start={"x": 2.0, "y": 3.0},
        use_start=True))
    assert plan.found


# ---------------------------------------------------------------------- item 12: the server
@pytest.mark.parametrize(("name", "service", "fields", "field"), [
    ("make_plan", "cyborg_msgs/srv/MakePlan", {"goal": {"x": math.nan}}, "goal.x"),
    ("make_plan", "cyborg_msgs/srv/MakePlan", {"goal": {"y": math.inf}}, "goal.y"),
    ("make_plan", "cyborg_msgs/srv/MakePlan",
     {"goal": {"x": 8.0, "y": 3.0}, "start": {"theta": -math.inf}, "use_start": True},
     "start.theta"),
    ("nav/get_distance_to_goal", "cyborg_msgs/srv/DistanceToGoal",
     {"goal": {"position": {"x": math.nan}}}, "goal.position.x"),
    ("nav/get_distance_to_goal", "cyborg_msgs/srv/DistanceToGoal",
     {"goal": {"position": {"y": -math.inf}}}, "goal.position.y"),
])
def test_poses_the_planner_cannot_use_are_refused_before_the_handler(
        robot: tuple[Node, Simulator], caplog: pytest.LogCaptureFixture, name: str,
        service: str, fields: dict[str, Any], field: str) -> None:
    """A NaN goal used to reach the planner and come back as "ValueError: cannot convert
    float NaN to integer", with the handler's traceback in the server's log."""
    node, _sim = robot
    caplog.set_level(logging.WARNING)
    with pytest.raises(RequestError) as caught:
        call(node, name, service, request(node, service, **fields))
    text = one_line(caught.value, f"/cyborg/{name}")
    assert f"bad request: {field}" in text
    located = [record for record in caplog.records if f"/cyborg/{name}" in record.getMessage()
               and field in record.getMessage()]
    assert located and all(record.exc_info is None for record in located)
    still_answers(node)


def test_load_map_file_refuses_a_path_with_a_nul_byte_or_a_fifo_in_one_line(
        robot: tuple[Node, Simulator], tmp_path: Path) -> None:
    node, sim = robot
    fifo = tmp_path / "pipe.map"
    os.mkfifo(fifo)
    for path in ("maps/a\x00b.map", str(fifo)):
        reply = call(node, "load_map_file", "cyborg_msgs/srv/LoadMapFile",
                     request(node, "cyborg_msgs/srv/LoadMapFile", path=path), timeout=5)
        assert not reply.success and "\n" not in reply.message
    assert sim.map.source == "room.map"


@pytest.mark.parametrize("slow_part", ["cyborg.nav.services.read_map",
                                       "cyborg.sim.simulator.choose_start"])
def test_stop_answers_while_a_map_loads(robot: tuple[Node, Simulator], tmp_path: Path,
                                        monkeypatch: pytest.MonkeyPatch, slow_part: str) -> None:
    """Reading runs beside the node's thread and the simulator builds the new world before it
    takes the simulation's lock, so the stop button is never queued behind a map."""
    node, sim = robot
    slow = threading.Event()
    module, _dot, name = slow_part.rpartition(".")
    real = getattr(__import__(module, fromlist=[name]), name)

    def slowly(*args: Any, **options: Any) -> Any:
        slow.wait(10)
        return real(*args, **options)

    monkeypatch.setattr(slow_part, slowly)
    path = write(tmp_path, "room2.map", ROOM)
    loading = node.create_client("load_map_file", "cyborg_msgs/srv/LoadMapFile").call_async(
        request(node, "cyborg_msgs/srv/LoadMapFile", path=str(path)), timeout=20)
    time.sleep(0.3)
    started = time.monotonic()
    assert call(node, "stop", TRIGGER, request(node, TRIGGER), timeout=3).success
    busy = call(node, "load_map_file", "cyborg_msgs/srv/LoadMapFile",
                request(node, "cyborg_msgs/srv/LoadMapFile", path=str(path)), timeout=3)
    assert not busy.success and "another map is loading" in busy.message
    assert time.monotonic() - started < 2.0
    slow.set()
    assert loading.result(timeout=20).success and sim.map.source == str(path)


def test_stop_answers_while_a_plan_is_slow(robot: tuple[Node, Simulator],
                                          monkeypatch: pytest.MonkeyPatch) -> None:
    """stop, dock and undock have a thread of their own: a slow make_plan (a large map) or
    closest-goal search on the node's thread never queues the stop button behind it."""
    node, _sim = robot
    slow = threading.Event()
    from cyborg.nav.services import NavigationMap
    real = NavigationMap.plan

    def slowly(self: NavigationMap, *args: Any, **options: Any) -> Any:
        slow.wait(10)
        return real(self, *args, **options)

    monkeypatch.setattr(NavigationMap, "plan", slowly)
    service = "cyborg_msgs/srv/MakePlan"
    planning = node.create_client("make_plan", service).call_async(
        request(node, service, goal={"x": 8.0, "y": 3.0}, start={"x": 2.0, "y": 3.0},
                              use_start=True), timeout=20)
    time.sleep(0.3)
    try:
        started = time.monotonic()
        assert call(node, "stop", TRIGGER, request(node, TRIGGER), timeout=3).success
        assert time.monotonic() - started < 2.0
    finally:
        slow.set()
    assert planning.result(timeout=20).found


@pytest.mark.parametrize("pose", [{"x": math.nan}, {"y": math.inf}, {"x": 8.0, "y": 3.0,
                                                                      "theta": math.nan}])
def test_move_to_goal_with_a_pose_that_is_not_finite_fails_to_plan(
        robot: tuple[Node, Simulator], pose: dict[str, float]) -> None:
    """The same NaN through the action: the planner refuses it instead of raising."""
    node, sim = robot
    before = sim.pose
    action = node.create_action_client("move_to_goal", "cyborg_msgs/action/MoveToGoal")
    goal = action.send_goal(new_message(node.types, "cyborg_msgs/action/MoveToGoal_Goal",
                                        {"pose": pose, "use_heading": True}))
    _status, result = goal.result(timeout=10)
    assert result.outcome == NO_PATH and "not a finite pose" in result.message
    assert "\n" not in result.message and sim.pose.distance_to(before) < 0.05


# ---------------------------------------------------------------------- item 12: the client
@pytest.mark.parametrize(("name", "service", "build", "field"), [
    ("make_plan", "cyborg_msgs/srv/MakePlan", lambda t: t("cyborg_msgs/srv/MakePlan_Request")(
        goal=t("geometry_msgs/msg/Pose2D")(x=1.0, y=0.0, theta=0.0), start=None,
        use_start=False), "start"),
    ("make_plan", "cyborg_msgs/srv/MakePlan", lambda t: t("cyborg_msgs/srv/MakePlan_Request")(
        goal="abc", start=t("geometry_msgs/msg/Pose2D")(x=0.0, y=0.0, theta=0.0),
        use_start=False), "goal"),
    ("make_plan", "cyborg_msgs/srv/MakePlan", lambda t: t("cyborg_msgs/srv/MakePlan_Request")(
        goal=t("geometry_msgs/msg/Pose2D")(x="1", y=0.0, theta=0.0),
        start=t("geometry_msgs/msg/Pose2D")(x=0.0, y=0.0, theta=0.0), use_start=False),
     "goal.x"),
    ("load_map_file", "cyborg_msgs/srv/LoadMapFile",
     lambda t: t("cyborg_msgs/srv/LoadMapFile_Request")(path=5), "path"),
    ("load_map_file", "cyborg_msgs/srv/LoadMapFile",
     lambda t: t("cyborg_msgs/srv/LoadMapFile_Request")(path="/tmp/\udcff.map"), "path"),
])
def test_wrong_field_types_are_one_line_errors_on_the_client(
        robot: tuple[Node, Simulator], name: str, service: str, build: Any,
        field: str) -> None:
    """These raised AttributeError or UnicodeEncodeError from deep inside the serialiser."""
    node, _sim = robot
    with pytest.raises(RequestError) as caught:
        call(node, name, service, build(node.types.message_class), timeout=2)
    text = one_line(caught.value, f"/cyborg/{name}")
    assert f"bad request: {field}:" in text


# ---------------------------------------------------------------------- handlers that fail
@pytest.fixture
def bus() -> Iterator[tuple[Context, Node, Node]]:
    with Context(BusConfig.isolated()) as context:
        yield context, Node("server", "/t", context=context), Node("client", "/t", context=context)


def test_a_raising_handler_is_one_line_for_the_caller_and_logged_once_with_its_traceback(
        bus: tuple[Context, Node, Node], caplog: pytest.LogCaptureFixture) -> None:
    _context, server, client = bus
    caplog.set_level(logging.WARNING)
    calls: list[int] = []
    response = server.types.message_class(f"{TRIGGER}_Response")

    def boom(_request: Any) -> Any:
        calls.append(1)
        if len(calls) <= 2:
            raise ValueError("first line\nTraceback (most recent call last):\n  secret")
        return response(success=True, message="fine")

    server.create_service("boom", TRIGGER, boom)
    for _ in range(2):
        with pytest.raises(ServiceError) as caught:
            call(client, "boom", TRIGGER, request(client, TRIGGER), timeout=5)
        text = one_line(caught.value, "/t/boom")
        assert "ValueError: first line" in text and "secret" not in text
    assert call(client, "boom", TRIGGER, request(client, TRIGGER)).message == "fine"
    logged = [record for record in caplog.records if "/t/boom" in record.getMessage()]
    assert len(logged) == 2 and logged[0].exc_info and not logged[1].exc_info


def test_a_response_that_cannot_be_sent_is_an_error_reply_not_a_timeout(
        bus: tuple[Context, Node, Node]) -> None:
    """The reply was marked sent before serialising, so the caller waited for its timeout."""
    _context, server, client = bus
    response = server.types.message_class(f"{TRIGGER}_Response")
    server.create_service("bad", TRIGGER, lambda _r: response(success=True, message=5))
    started = time.monotonic()
    with pytest.raises(ServiceError) as caught:
        call(client, "bad", TRIGGER, request(client, TRIGGER), timeout=5)
    assert not isinstance(caught.value, ServiceTimeoutError)
    assert time.monotonic() - started < 3.0
    text = one_line(caught.value, "/t/bad")
    assert "bad response" in text and "message: expected text" in text


def test_garbage_and_multi_line_errors_stay_one_line(bus: tuple[Context, Node, Node]) -> None:
    context, server, client = bus
    response = server.types.message_class(f"{TRIGGER}_Response")
    server.create_service("ok", TRIGGER, lambda _r: response(success=True, message="ok"))
    key = client.create_client("ok", TRIGGER).key
    for payload in (b"", b"\x00\x01\x00\x00", b"\x00\x01\x00\x00" + b"\xff" * 64, b"\x07" * 9):
        errors = [reply.err.payload.to_string() for reply in context.session.get(
            key, payload=payload, timeout=3) if reply.err is not None]
        assert errors and "\n" not in errors[0] and errors[0].startswith("bad request: ")
    assert call(client, "ok", TRIGGER, request(client, TRIGGER)).message == "ok"
    # a server elsewhere answering with several lines still gives the caller one
    lying = client.create_client("liar", TRIGGER)

    def reply_err(query: zenoh.Query) -> None:
        query.reply_err(b"RuntimeError: x\nTraceback (most recent call last):\n  File ...")
        query.drop()

    queryable = context.session.declare_queryable(lying.key, reply_err, complete=True)
    try:
        with pytest.raises(ServiceError) as caught:
            lying.call(request(client, TRIGGER), timeout=3)
        assert "RuntimeError: x" in one_line(caught.value, "/t/liar")
    finally:
        queryable.undeclare()


# ---------------------------------------------------------------------- fuzzing
_FLOAT = st.one_of(st.floats(-20, 20), st.floats(allow_nan=True, allow_infinity=True),
                   st.sampled_from([math.nan, math.inf, -math.inf, 1e300, -1e300, 0.0]))
_POSE2D = st.fixed_dictionaries({}, optional={"x": _FLOAT, "y": _FLOAT, "theta": _FLOAT})
_POSE = st.fixed_dictionaries({}, optional={
    "position": st.fixed_dictionaries({}, optional={"x": _FLOAT, "y": _FLOAT, "z": _FLOAT}),
    "orientation": st.fixed_dictionaries({}, optional={
        "x": _FLOAT, "y": _FLOAT, "z": _FLOAT, "w": _FLOAT})})
_CALLS: st.SearchStrategy[tuple[str, str, dict[str, Any]]] = st.one_of(
    st.tuples(st.just("make_plan"), st.just("cyborg_msgs/srv/MakePlan"),
              st.fixed_dictionaries({}, optional={"goal": _POSE2D, "start": _POSE2D,
                                                  "use_start": st.booleans()})),
    st.tuples(st.just("nav/get_distance_to_goal"), st.just("cyborg_msgs/srv/DistanceToGoal"),
              st.fixed_dictionaries({}, optional={"goal": _POSE})),
    st.tuples(st.just("load_map_file"), st.just("cyborg_msgs/srv/LoadMapFile"),
              st.fixed_dictionaries({"path": st.one_of(
                  st.text(max_size=30), st.sampled_from(["", ".", "/", "/dev/zero",
                                                         "/etc/passwd", "\x00"]))})),
    st.sampled_from([("nav/get_closest_goal", "cyborg_msgs/srv/ClosestGoal", {}),
                     ("nav/get_available_goals", "cyborg_msgs/srv/AvailableGoals", {})]),
    st.tuples(st.sampled_from(["stop", "undock"]), st.just(TRIGGER), st.just({})),
)


@settings(max_examples=120, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(case=_CALLS)
def test_fuzz_typed_requests_get_an_answer_or_one_line(robot: tuple[Node, Simulator],
                                                        case: tuple[str, str, dict[str, Any]]
                                                        ) -> None:
    node, _sim = robot
    name, service, fields = case
    message = request(node, service, **fields)
    started = time.monotonic()
    try:
        call(node, name, service, message, timeout=10)
        event("answered")
    except ServiceTimeoutError:
        pytest.fail(f"{name} did not answer {fields!r}")
    except ServiceError as exc:
        event(type(exc).__name__)
        assert "is not available" not in one_line(exc, f"/cyborg/{name}")
    assert time.monotonic() - started < 10


@settings(max_examples=120, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(name=st.sampled_from(["make_plan", "nav/get_distance_to_goal", "load_map_file",
                             "stop"]),
       payload=st.one_of(st.binary(max_size=80),
                         st.binary(max_size=80).map(lambda raw: b"\x00\x01\x00\x00" + raw)))
def test_fuzz_garbage_payloads_get_one_line_and_the_services_keep_answering(
        robot: tuple[Node, Simulator], name: str, payload: bytes) -> None:
    node, _sim = robot
    service = {"make_plan": "cyborg_msgs/srv/MakePlan",
               "nav/get_distance_to_goal": "cyborg_msgs/srv/DistanceToGoal",
               "load_map_file": "cyborg_msgs/srv/LoadMapFile", "stop": TRIGGER}[name]
    key = node.create_client(name, service).key
    replies = list(node.context.session.get(key, payload=payload, timeout=10))
    assert replies
    for reply in replies:
        if reply.err is not None:
            text = reply.err.payload.to_string()
            assert "\n" not in text and text != "Timeout", text


def test_after_the_fuzzing_every_service_still_answers(robot: tuple[Node, Simulator]) -> None:
    node, _sim = robot
    still_answers(node)
    assert call(node, "stop", TRIGGER, request(node, TRIGGER)).success
