"""The monitor's timeline over a played recording (cyborg.monitor.player_link and
player_source): a player on the bus is found and its state sent to every page as ``player``;
the seat's holder pauses, seeks and steps it; the tree and the robot follow the played time
after a seek, and the kept history starts over; every bad field is refused by name, as are
pages without the seat; a player that leaves is told as ``player: null``."""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from cyborg.bus import BusConfig, Context, Node
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import PlayerState
from cyborg.interfaces import player as contract
from cyborg.monitor import Monitor
from cyborg.monitor.client import Client
from cyborg.monitor.player_link import PLAYER_INTERVAL
from cyborg.monitor.player_source import view_of
from cyborg.monitor.seat import NOT_HOLDER, VIEW_ONLY
from cyborg.record.playback_source import Recording, open_recording
from cyborg.record.player import Player
from tests.monitor.monitor_protocol import local_client, next_json, receive_until
from tests.monitor.played_runs import (
    DURATION,
    HALF,
    ROBOT,
    RUNNING,
    SUCCESS,
    TREE,
    write_played_run,
)
from tests.running_system import wait_until


@pytest.fixture(scope="module")
def run_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("played") / "shift.mcap"
    write_played_run(path)
    return path


@pytest.fixture
def bus() -> Iterator[Context]:
    with Context(BusConfig.isolated()) as context:
        yield context


@pytest.fixture
def monitor(bus: Context) -> Iterator[Monitor]:
    monitor = Monitor(Node("monitor", "/cyborg", context=bus), namespaces=[TREE])
    try:
        yield monitor
    finally:
        monitor.stop()


@pytest.fixture
def playing(bus: Context, run_file: Path) -> Iterator[Player]:
    recording: Recording = open_recording(run_file, bus.types)
    player = Player(Node(contract.NAME, context=bus), recording, paused=True)
    try:
        yield player
    finally:
        player.close()
        recording.close()


def _player(socket: Any, accept: Callable[[dict[str, Any] | None], bool],
            limit: int = 400) -> dict[str, Any] | None:
    """The next ``player`` message's content that ``accept`` takes."""
    for _ in range(limit):
        message = receive_until(socket, "player")
        if accept(message["player"]):
            found: dict[str, Any] | None = message["player"]
            return found
    raise AssertionError("no such player message")


def _answer(socket: Any, command: dict[str, Any]) -> dict[str, Any]:
    socket.send_json(command)
    while True:
        message = next_json(socket)
        if message["t"] == "result" and message["req"] == command.get("req"):
            return message


def _holding_the_seat(socket: Any) -> None:
    socket.send_json({"t": "hello"})
    receive_until(socket, "seat")
    assert _answer(socket, {"t": "claim", "req": 0})["ok"] is True


def _status_of(monitor: Monitor, node: str) -> int:
    source = monitor.hub.sources.get(TREE)
    state = source.state if source is not None else None
    return int(state.status[state.index_of[node]]) if state is not None else -1


def _pose_x(monitor: Monitor) -> float:
    robot = monitor.hub.robot_hub.robots.get(ROBOT)
    pose = robot.source.pose if robot is not None else None
    return pose[0] if pose is not None else math.nan


def test_the_seat_holder_pauses_seeks_and_steps_and_the_tree_and_robot_follow(
        monitor: Monitor, playing: Player) -> None:
    with local_client(monitor.app) as client, client.websocket_connect("/ws") as socket:
        _holding_the_seat(socket)
        shown = _player(socket, lambda p: p is not None)
        assert shown is not None
        assert shown["file"] == "shift.mcap" and shown["ns"] == "/"
        assert shown["duration"] == pytest.approx(DURATION) and shown["rate"] == 1.0
        assert shown["paused"] is True and shown["position"] == 0.0

        resumed = _answer(socket, {"t": "player_pause", "paused": False, "req": 1})
        assert resumed["ok"] is True and resumed["command"] == "player_pause", resumed
        _player(socket, lambda p: p is not None and not p["paused"] and p["position"] > 0.3)
        assert _answer(socket, {"t": "player_pause", "paused": True, "req": 2})["ok"]
        _player(socket, lambda p: p is not None and p["paused"])

        late = _answer(socket, {"t": "player_seek", "position": 3.0, "req": 3})
        assert late["ok"] is True, late
        at = _player(socket, lambda p: p is not None and p["position"] == 3.0)
        assert at is not None and at["paused"] is True, "a seek keeps the player paused"
        wait_until(lambda: _status_of(monitor, "work") == SUCCESS, 20, "work done at 3 s")
        wait_until(lambda: _pose_x(monitor) == pytest.approx(2.9), 20, "the robot at 2.9 s")

        back = _answer(socket, {"t": "player_seek", "position": 1.05, "req": 4})
        assert back["ok"] is True
        again = _player(socket, lambda p: p is not None and p["position"] == 1.05)
        assert again is not None and again["jumps"] > at["jumps"]
        # the state at 1.05 s, not what 3 s left: the tree starts over (structure sent again)
        # with the last tick before it, the robot where it was
        wait_until(lambda: _status_of(monitor, "work") == RUNNING, 20, "work running at 1 s")
        wait_until(lambda: _pose_x(monitor) == pytest.approx(1.0), 20, "the robot at 1 s")
        assert _status_of(monitor, "rest") == 0, "rest never ran before 1.05 s"
        socket.send_json({"t": "watch", "ns": TREE})
        socket.send_json({"t": "history"})
        kept = receive_until(socket, "history")["ticks"]
        assert kept and all(entry[1] < HALF for entry in kept), "no tick of the other timeline"

        stepped = _answer(socket, {"t": "player_step", "req": 5})
        assert stepped["ok"] is True, stepped
        _player(socket, lambda p: p is not None and p["paused"] and p["position"] == 1.1)
        state = monitor.hub.sources[TREE].state
        assert state is not None
        wait_until(lambda: state.tick == 11, 20, "the step to play the tick at 1.1 s")

        assert _answer(socket, {"t": "player_seek", "position": 0, "req": 6})["ok"] is True
        # before the first message nothing of the tree has run: it starts over
        wait_until(lambda: monitor.hub.sources[TREE].state is not state, 20, "a new state")
        fresh = monitor.hub.sources[TREE].state
        assert fresh is not None and fresh.tick == 0 and _status_of(monitor, "work") == 0


@pytest.mark.parametrize(("command", "field"), [
    ({"t": "player_pause"}, "paused"),
    ({"t": "player_pause", "paused": "yes"}, "paused"),
    ({"t": "player_pause", "paused": 1}, "paused"),
    ({"t": "player_pause", "paused": None}, "paused"),
    ({"t": "player_seek"}, "position"),
    ({"t": "player_seek", "position": "1.5"}, "position"),
    ({"t": "player_seek", "position": True}, "position"),
    ({"t": "player_seek", "position": None}, "position"),
    ({"t": "player_seek", "position": [1.0]}, "position"),
    ({"t": "player_seek", "position": -0.001}, "position"),
    ({"t": "player_seek", "position": DURATION + 0.001}, "position"),
    ({"t": "player_seek", "position": 1e300}, "position"),
])
def test_every_bad_field_is_refused_naming_it(monitor: Monitor, playing: Player,
                                              command: dict[str, Any], field: str) -> None:
    with local_client(monitor.app) as client, client.websocket_connect("/ws") as socket:
        _holding_the_seat(socket)
        _player(socket, lambda p: p is not None)
        refused = _answer(socket, {**command, "req": 7})
        assert refused["ok"] is False and refused["field"] == field, refused
        assert f"field {field}: {field} " in refused["message"], refused["message"]
        assert refused["command"] == command["t"]
        assert playing.paused and playing.position == 0.0, "nothing reached the player"


def test_a_number_json_cannot_carry_is_an_error_naming_the_message(
        monitor: Monitor, playing: Player) -> None:
    with local_client(monitor.app) as client, client.websocket_connect("/ws") as socket:
        _holding_the_seat(socket)
        socket.send_text('{"t": "player_seek", "position": NaN, "req": 8}')
        error = receive_until(socket, "error")
        assert error["message"].startswith("message 3"), error
        assert playing.position == 0.0


def test_pages_without_the_seat_see_the_position_but_are_refused(
        monitor: Monitor, playing: Player) -> None:
    with local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as holder, client.websocket_connect("/ws") as other, \
            local_client(monitor.app, peer="192.0.2.7") as remote, \
            remote.websocket_connect("/ws") as viewer:
        _holding_the_seat(holder)
        for page, why in ((other, NOT_HOLDER), (viewer, VIEW_ONLY)):
            page.send_json({"t": "hello"})
            assert _player(page, lambda p: p is not None) is not None
            commands: list[dict[str, Any]] = [{"t": "player_pause", "paused": False},
                                              {"t": "player_seek", "position": 1.0},
                                              {"t": "player_step"}]
            for number, command in enumerate(commands):
                refused = _answer(page, {**command, "req": 20 + number})
                assert refused["ok"] is False and why in refused["message"], refused
        assert playing.paused and playing.position == 0.0


def test_no_player_refuses_and_a_player_that_leaves_is_told_as_null(
        bus: Context, monitor: Monitor, run_file: Path) -> None:
    with local_client(monitor.app) as client, client.websocket_connect("/ws") as socket:
        socket.send_json({"t": "hello"})
        assert receive_until(socket, "player")["player"] is None, "said in answer to hello"
        assert _answer(socket, {"t": "claim", "req": 0})["ok"] is True
        refused = _answer(socket, {"t": "player_step", "req": 1})
        assert refused["ok"] is False and "no player is on the bus" in refused["message"]
        recording = open_recording(run_file, bus.types)
        player = Player(Node(contract.NAME, context=bus), recording, paused=True)
        try:
            assert _player(socket, lambda p: p is not None) is not None
        finally:
            player.close()
            recording.close()
        assert _player(socket, lambda p: p is None) is None
        wait_until(lambda: monitor.hub.player.source is None, 20, "the player let go")


def test_the_state_goes_to_pages_at_most_four_times_a_second(
        monitor: Monitor, playing: Player, monkeypatch: pytest.MonkeyPatch) -> None:
    sent: list[float] = []
    send = Client.send

    def noting(client: Client, message: dict[str, Any] | str) -> None:
        if isinstance(message, str) and message.startswith('{"t":"player","player":{'):
            sent.append(time.monotonic())
        send(client, message)

    monkeypatch.setattr(Client, "send", noting)
    with local_client(monitor.app) as client, client.websocket_connect("/ws") as socket:
        _player(socket, lambda p: p is not None)
        playing.set_paused(False)
        _player(socket, lambda p: p is not None and p["position"] >= 2.0)
    gaps = [later - earlier for earlier, later in itertools.pairwise(sent)]
    assert len(gaps) >= 4, "the position went out as it played"
    assert min(gaps) >= PLAYER_INTERVAL - 1e-3, gaps


def _state(**fields: Any) -> PlayerState:
    values: dict[str, Any] = {"position": 1.0, "duration": 4.0, "rate": 1.0, "paused": False,
                              "finished": False, "recording_time": Time(sec=5, nanosec=0),
                              "source": "/runs/shift.mcap"}
    return PlayerState(**{**values, **fields})


@pytest.mark.parametrize(("fields", "named"), [
    ({"position": math.nan}, "position"), ({"duration": math.inf}, "duration"),
    ({"rate": math.nan}, "rate"), ({"duration": -1.0, "position": 0.0}, "duration"),
    ({"position": 4.5}, "position"), ({"position": -0.5}, "position"), ({"rate": 0.0}, "rate"),
])
def test_a_state_that_cannot_be_drawn_is_refused_naming_the_field(fields: dict[str, Any],
                                                                  named: str) -> None:
    with pytest.raises(ValueError, match=f"^{named} "):
        view_of(_state(**fields))


def test_a_drawable_state_keeps_the_file_name_only() -> None:
    view = view_of(_state())
    assert view.wire() == {"file": "shift.mcap", "duration": 4.0, "position": 1.0,
                           "rate": 1.0, "paused": False, "finished": False, "time": 5.0}


def test_while_a_recording_plays_commands_that_act_are_refused_but_stops_go_out(
        monitor: Monitor, playing: Player) -> None:
    """The page disables acting while a recording plays; the monitor refuses it too (a page
    of its own, a script), never a stop or a disable."""
    with local_client(monitor.app) as client, client.websocket_connect("/ws") as socket:
        _holding_the_seat(socket)
        _player(socket, lambda p: p is not None)
        acting: list[dict[str, Any]] = [
            {"t": "go", "ns": ROBOT, "goal": "Office"},
            {"t": "go_pose", "ns": ROBOT, "pose": [1.0, 2.0, 0.0]},
            {"t": "drive", "ns": ROBOT, "vx": 0.2, "wz": 0.0},
            {"t": "enable", "ns": TREE, "on": True},
            {"t": "step", "ns": TREE},
            {"t": "mode_force", "ns": TREE, "mode": "demo"}]
        for number, command in enumerate(acting, start=10):
            refused = _answer(socket, {**command, "req": number})
            assert refused["ok"] is False, refused
            assert "refused while a recording plays (cyborg play)" in refused["message"], refused
        stops: list[dict[str, Any]] = [{"t": "stop", "ns": ROBOT},
                                       {"t": "enable", "ns": TREE, "on": False}]
        for number, stop in enumerate(stops, start=30):
            answer = _answer(socket, {**stop, "req": number})
            assert "recording plays" not in answer.get("message", ""), answer
