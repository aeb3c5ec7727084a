"""The player: a recording made by the recorder, played into another process's subscribers —
every message, its bytes, its order, latched ones latched, /clock, start, topics, loop, and the
pause, step and seek services with the latched state."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from cyborg.bus import Context, Node
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import PlayerState
from cyborg.bus.msgs.cyborg_msgs.srv import Seek_Request
from cyborg.bus.msgs.rosgraph_msgs.msg import Clock
from cyborg.bus.msgs.std_srvs.srv import SetBool_Request, Trigger_Request
from cyborg.bus.wire import EntityKind
from cyborg.interfaces import player as contract
from cyborg.record.mcap_file import McapFile
from cyborg.record.playback_source import Recording, open_recording
from cyborg.record.player import Player, topic_filter
from tests.bus.bus_peer import linked_contexts, until_served, until_subscribed, wait_for
from tests.record.playing import CHATTER, SPACING, Listener, record_run

STRING = "std_msgs/msg/String"


@pytest.fixture(scope="module")
def run_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("run") / "run.mcap"
    record_run(path)
    return path


@pytest.fixture
def buses() -> Iterator[tuple[Context, Context]]:
    """(the player's bus, the listeners' bus): two processes' worth of bus, linked."""
    with linked_contexts() as pair:
        yield pair


def recorded(path: Path, bus: Context) -> dict[str, list[bytes]]:
    recording = open_recording(path, bus.types)
    try:
        found: dict[str, list[bytes]] = {}
        for played in recording.messages():
            found.setdefault(played.topic, []).append(played.data)
        return found
    finally:
        recording.close()


def start_player(bus: Context, path: Path, **options: object) -> tuple[Player, Recording]:
    recording = open_recording(path, bus.types)
    return Player(Node(contract.NAME, context=bus), recording, **options), recording  # type: ignore[arg-type]


def test_every_message_arrives_as_recorded_in_order_with_its_spacing_and_the_map_latched(
        run_file: Path, buses: tuple[Context, Context]) -> None:
    playing, listening = buses
    expected = recorded(run_file, playing)
    reading = open_recording(run_file, playing.types)
    logged = [p.log_time for p in reading.messages() if p.topic == "/chatter"]
    reading.close()
    listener = Listener(Node("listener", context=listening))
    listener.listen("/chatter", STRING)
    clock: list[Clock] = []
    Node("clock", context=listening).create_subscription("/clock", Clock, clock.append)
    player, recording = start_player(playing, run_file, paused=True)
    try:
        until_subscribed(playing, "/chatter", 20)
        player.set_paused(False)
        assert wait_for(lambda: len(listener.data("/chatter")) == CHATTER, 30)
        assert listener.data("/chatter") == expected["/chatter"]
        arrivals = [raw.received_ns for raw in listener.got["/chatter"]]
        assert logged[-1] - logged[0] >= (CHATTER - 1) * SPACING * 0.5e9
        # played at its pace, not all at once (precision is the benchmark's)
        assert arrivals[-1] - arrivals[0] >= 0.5 * (logged[-1] - logged[0])
        assert player.wait_finished(30)
        late = Listener(Node("late", context=listening))
        late.listen("/map", STRING, latched=True)
        assert wait_for(lambda: late.data("/map") == expected["/map"], 20)
        assert wait_for(lambda: clock, 10)
        times = [c.clock.sec * 1_000_000_000 + c.clock.nanosec for c in clock]
        assert times == sorted(times)
        assert recording.start_ns <= times[0] and times[-1] <= recording.end_ns
        assert times[-1] - times[0] >= 0.5 * (logged[-1] - logged[0])
    finally:
        player.close()
        recording.close()


def test_start_plays_from_there_after_the_latched_values_before_it(
        run_file: Path, buses: tuple[Context, Context]) -> None:
    playing, listening = buses
    expected = recorded(run_file, playing)
    listener = Listener(Node("listener", context=listening))
    listener.listen("/chatter", STRING)
    listener.listen("/map", STRING, latched=True)
    recording = open_recording(run_file, playing.types)
    half = recording.duration / 2
    cut = recording.start_ns + int(half * 1e9)
    after = [p.data for p in recording.messages(cut) if p.topic == "/chatter"]
    assert 0 < len(after) < CHATTER
    player = Player(Node(contract.NAME, context=playing), recording, start=half, paused=True)
    try:
        until_subscribed(playing, "/chatter", 20)
        assert wait_for(lambda: listener.data("/map") == expected["/map"], 20)
        player.set_paused(False)
        assert player.wait_finished(30)
        assert wait_for(lambda: listener.data("/chatter") == after, 20), listener.data("/chatter")
    finally:
        player.close()
        recording.close()


def test_only_the_chosen_topics_are_published(run_file: Path,
                                              buses: tuple[Context, Context]) -> None:
    playing, listening = buses
    player, recording = start_player(playing, run_file, paused=True,
                                     accept=topic_filter([], ["/ma*"]))
    try:
        assert set(player.topics) == {"/chatter"}
        assert wait_for(lambda: listening.graph.count("/chatter", EntityKind.PUBLISHER), 20)
        assert listening.graph.count("/map", EntityKind.PUBLISHER) == 0
        assert set(topic_filter(["/map"], [])(t) for t in ("/map", "/chatter")) == {True, False}
    finally:
        player.close()
        recording.close()


def test_loop_plays_the_recording_again(run_file: Path,
                                        buses: tuple[Context, Context]) -> None:
    playing, listening = buses
    expected = recorded(run_file, playing)
    listener = Listener(Node("listener", context=listening))
    listener.listen("/chatter", STRING)
    player, recording = start_player(playing, run_file, rate=4.0, loop=True, paused=True)
    try:
        until_subscribed(playing, "/chatter", 20)
        player.set_paused(False)
        assert wait_for(lambda: len(listener.data("/chatter")) >= 2 * CHATTER, 60)
        assert listener.data("/chatter")[:2 * CHATTER] == 2 * expected["/chatter"]
        assert player.stats.loops >= 1 and not player.finished
    finally:
        player.close()
        recording.close()


def test_pause_step_and_seek_by_service_with_the_state_latched(
        run_file: Path, buses: tuple[Context, Context]) -> None:
    playing, listening = buses
    expected = recorded(run_file, playing)
    listener = Listener(Node("listener", context=listening))
    listener.listen("/chatter", STRING)
    listener.listen("/map", STRING, latched=True)
    states: list[PlayerState] = []
    lock = threading.Lock()

    def on_state(state: PlayerState) -> None:
        with lock:
            states.append(state)

    timeline = Node("timeline", context=listening)
    contract.STATE.subscription(timeline, on_state, namespace="/")
    pause, step = contract.PAUSE.client(timeline, "/"), contract.STEP.client(timeline, "/")
    seek = contract.SEEK.client(timeline, "/")
    player, recording = start_player(playing, run_file, paused=True)
    try:
        until_subscribed(playing, "/chatter", 20)
        until_served(listening, "/player/step", 20)
        assert wait_for(lambda: states and states[-1].paused, 20)
        assert states[-1].duration == pytest.approx(recording.duration)
        chatter = expected["/chatter"]
        for stepped in range(3):  # the map (recorded first), then one message of /chatter each
            assert step.call(Trigger_Request(), timeout=20).success
            want = chatter[:stepped]
            assert wait_for(lambda want=want: listener.data("/chatter") == want  # type: ignore[misc]
                            and listener.data("/map") == expected["/map"], 20), stepped
        refused = seek.call(Seek_Request(position=recording.duration + 5), timeout=20)
        assert not refused.success and "position" in refused.message
        assert seek.call(Seek_Request(position=0.0), timeout=20).success
        for _ in range(2):
            assert step.call(Trigger_Request(), timeout=20).success
        assert wait_for(lambda: listener.data("/chatter") == chatter[:2] + chatter[:1], 20)
        assert states[-1].paused and not player.finished
        assert pause.call(SetBool_Request(data=False), timeout=20).success
        assert player.wait_finished(30)
        assert wait_for(lambda: states[-1].finished and not states[-1].paused, 20)
        assert states[-1].position == pytest.approx(recording.duration)
        assert str(run_file) == states[-1].source
    finally:
        player.close()
        recording.close()


def test_out_of_range_arguments_are_refused_naming_them(run_file: Path,
                                                        buses: tuple[Context, Context]) -> None:
    playing, _ = buses
    recording = open_recording(run_file, playing.types)
    try:
        with pytest.raises(ValueError, match="rate"):
            Player(Node("p1", context=playing), recording, rate=0)
        with pytest.raises(ValueError, match="start"):
            Player(Node("p2", context=playing), recording, start=recording.duration + 1)
    finally:
        recording.close()


def test_a_recording_with_its_own_clock_plays_that_one_and_makes_none(
        buses: tuple[Context, Context], tmp_path: Path) -> None:
    playing, listening = buses
    path = tmp_path / "clocked.mcap"
    file = McapFile(path, playing.types)
    channel = file.channel("/clock", "rosgraph_msgs/msg/Clock", [])
    recorded_clock = [bytes(playing.types.serialize(Clock(clock=Time(sec=s, nanosec=0)),
                                                   "rosgraph_msgs/msg/Clock")) for s in (7, 8)]
    for number, data in enumerate(recorded_clock):
        file.write(channel, 1_000 + number * 10_000_000, 0, data)
    file.close()
    listener = Listener(Node("listener", context=listening))
    listener.listen("/clock", "rosgraph_msgs/msg/Clock")
    player, recording = start_player(playing, path, paused=True)
    try:
        assert not player.own_clock
        until_subscribed(playing, "/clock", 20)
        player.set_paused(False)
        assert player.wait_finished(30)
        assert wait_for(lambda: listener.data("/clock") == recorded_clock, 20)
        assert playing.graph.count("/clock", EntityKind.PUBLISHER) == 1
    finally:
        player.close()
        recording.close()


def test_a_seek_sends_each_topics_recent_last_message_so_a_paused_timeline_shows_that_time(
        run_file: Path, buses: tuple[Context, Context]) -> None:
    playing, listening = buses
    expected = recorded(run_file, playing)
    listener = Listener(Node("listener", context=listening))
    listener.listen("/chatter", STRING)
    listener.listen("/map", STRING, latched=True)
    recording = open_recording(run_file, playing.types)
    chatter_times = [p.log_time for p in recording.messages() if p.topic == "/chatter"]
    player = Player(Node(contract.NAME, context=playing), recording, paused=True)
    try:
        until_subscribed(playing, "/chatter", 20)
        until_subscribed(playing, "/map", 20)
        just_before_tenth = (chatter_times[10] - recording.start_ns) / 1e9 - 0.001
        player.seek(just_before_tenth)
        assert wait_for(lambda: listener.data("/chatter") == [expected["/chatter"][9]], 20)
        assert wait_for(lambda: listener.data("/map") == expected["/map"], 20)
        assert player.paused, "a seek keeps the player paused"
        player.seek(0.0)  # nothing lies before the start: the map is its first message
        player.step()
        assert wait_for(lambda: listener.data("/map") == 2 * expected["/map"], 20)
        assert listener.data("/chatter") == [expected["/chatter"][9]]
    finally:
        player.close()
        recording.close()
