"""What the bus commands learn from the graph (types, durability), how they print messages and
how ``topic hz`` measures a rate.

In-process and quick: a :class:`Graph` fed tokens by hand stands for the bus, a timer thread for
a publisher that starts late. The same behaviour across processes is in ``test_bus_cli.py``.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator

import pytest

from cyborg.app.bus_lookup import echo_qos, service_type, topic_type
from cyborg.app.errors import CommandError
from cyborg.app.rate_window import Rate, RateWindow, hz_line
from cyborg.bus import Durability, MessageTypes, Qos, new_message, to_plain
from cyborg.bus.graph import Graph
from cyborg.bus.wire import EntityKind, endpoint_token

TYPES = MessageTypes()
_ids = iter(range(1, 1_000_000))


def token(kind: EntityKind, name: str, type_name: str = "std_msgs/msg/String",
          qos: Qos | None = None) -> str:
    """A liveliness key as a peer process would declare it."""
    return endpoint_token(0, "1f2e", 1, next(_ids), kind, "/", "peer", name, type_name,
                          "RIHS01_" + "0" * 64, qos or Qos())


@pytest.fixture
def later() -> Iterator[list[threading.Timer]]:
    """Timers started in a test; cancelled after it, so none outlives it."""
    timers: list[threading.Timer] = []
    yield timers
    for timer in timers:
        timer.cancel()


def appear_later(graph: Graph, key: str, timers: list[threading.Timer]) -> None:
    timers.append(threading.Timer(0.3, graph.add, [key]))
    timers[-1].start()


# ---------------------------------------------------------------------- messages as text
def test_to_plain_gives_every_field_and_no_constant() -> None:
    status = to_plain(new_message(TYPES, "cyborg_msgs/msg/BatteryStatus", {"charging_state": -1}))
    assert list(status) == ["header", "charging_state", "charge_percent", "voltage", "charging",
                            "dock_state"]  # not CHARGING_UNKNOWN and its kin
    battery = to_plain(new_message(TYPES, "sensor_msgs/msg/BatteryState",
                                   {"percentage": 0.5, "power_supply_status": 2}))
    assert "POWER_SUPPLY_STATUS_CHARGING" not in battery and "__msgtype__" not in battery
    assert battery["percentage"] == 0.5 and battery["power_supply_status"] == 2
    fix = to_plain(new_message(TYPES, "sensor_msgs/msg/NavSatFix", {}))
    assert set(fix["status"]) == {"status", "service"}  # nested: NavSatStatus has constants too
    for type_name, (_constants, fields) in TYPES.store.fielddefs.items():
        plain = to_plain(new_message(TYPES, type_name, {}))
        assert list(plain) == [name for name, _ in fields], type_name


# ---------------------------------------------------------------------- durability
@pytest.mark.parametrize(("publishers", "forced", "latched"), [
    ([Qos()], False, False),
    ([Qos.latched()], False, True),
    ([Qos(), Qos.latched(depth=5)], False, True),  # on Zenoh it still hears the volatile one
    ([Qos()], True, True),                          # --latched
    ([], False, True),                              # a publisher that starts later is heard
])
def test_echo_asks_for_latched_messages_when_a_publisher_keeps_them(
        publishers: list[Qos], forced: bool, latched: bool) -> None:
    graph = Graph(0)
    graph.add(token(EntityKind.SUBSCRIPTION, "/status", qos=Qos.latched()))  # does not count
    for qos in publishers:
        graph.add(token(EntityKind.PUBLISHER, "/status", qos=qos))
    chosen = echo_qos(graph, "status", latched=forced)
    assert (chosen.durability is Durability.TRANSIENT_LOCAL) is latched
    assert chosen.depth > 1  # an echo does not drop messages that come in a burst


# ---------------------------------------------------------------------- types
def test_a_known_topic_gives_its_type_without_waiting(capsys: pytest.CaptureFixture[str]
                                                      ) -> None:
    graph = Graph(0)
    graph.add(token(EntityKind.SUBSCRIPTION, "/robot/pose", "geometry_msgs/msg/Pose2D"))
    assert topic_type(graph, TYPES, "robot/pose", command="cyborg topic echo",
                      timeout=0.1) == "geometry_msgs/msg/Pose2D"
    assert capsys.readouterr().err == ""


def test_an_unknown_topic_is_waited_for(capsys: pytest.CaptureFixture[str],
                                        later: list[threading.Timer]) -> None:
    graph = Graph(0)
    appear_later(graph, token(EntityKind.PUBLISHER, "/late", "sensor_msgs/msg/BatteryState"),
                 later)
    assert topic_type(graph, TYPES, "/late", command="cyborg topic echo",
                      timeout=10) == "sensor_msgs/msg/BatteryState"
    assert capsys.readouterr().err == (
        "waiting for a publisher of /late to learn its type (to skip waiting, give the type: "
        "cyborg topic echo /late TYPE)\n")


def test_waiting_for_a_topic_has_a_limit() -> None:
    with pytest.raises(CommandError, match=r"no publisher of /never appeared within 0\.2 s"):
        topic_type(Graph(0), TYPES, "/never", command="cyborg topic hz", timeout=0.2)


def test_a_topic_with_two_types_or_an_unknown_type_is_an_error() -> None:
    graph = Graph(0)
    graph.add(token(EntityKind.PUBLISHER, "/mixed", "std_msgs/msg/String"))
    graph.add(token(EntityKind.PUBLISHER, "/mixed", "std_msgs/msg/Bool"))
    graph.add(token(EntityKind.PUBLISHER, "/odd", "cyborg_msgs/msg/BehaviorTree"))
    with pytest.raises(CommandError, match="several types"):
        topic_type(graph, TYPES, "/mixed", command="cyborg topic echo", timeout=0.1)
    with pytest.raises(CommandError, match="not registered here"):
        topic_type(graph, MessageTypes(interface_dirs=()), "/odd", command="x", timeout=0.1)


def test_a_service_call_waits_for_a_server(capsys: pytest.CaptureFixture[str],
                                           later: list[threading.Timer]) -> None:
    graph = Graph(0)
    graph.add(token(EntityKind.SERVICE_CLIENT, "/add", "example_interfaces/srv/AddTwoInts"))
    appear_later(graph, token(EntityKind.SERVICE_SERVER, "/add",
                              "example_interfaces/srv/AddTwoInts"), later)
    assert service_type(graph, TYPES, "add", None,
                        timeout=10) == "example_interfaces/srv/AddTwoInts"
    assert "waiting for service /add to become available" in capsys.readouterr().err
    assert service_type(graph, TYPES, "/add", "std_srvs/srv/Trigger",
                        timeout=0.1) == "std_srvs/srv/Trigger"  # a given type is kept
    with pytest.raises(CommandError, match=r"no server of /other appeared within 0\.2 s"):
        service_type(graph, TYPES, "/other", "std_srvs/srv/Trigger", timeout=0.2)


# ---------------------------------------------------------------------- topic hz
class FakeClock:
    """Seconds that pass only when a test says so."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def publish(window: RateWindow, clock: FakeClock, hz: float, seconds: int) -> list[Rate | None]:
    """``seconds`` report periods of 1 s in which a publisher sends at ``hz`` (0: it is silent),
    with the report ``topic hz`` makes at the end of each."""
    start = clock.now
    sends = [start + k / hz for k in range(1, round(hz * seconds) + 1)] if hz else []
    reports: list[Rate | None] = []
    for second in range(1, seconds + 1):
        while sends and sends[0] <= start + second + 1e-9:
            clock.now = sends.pop(0)
            window.arrived()
        clock.now = start + second
        reports.append(window.report())
    return reports


def rates(reports: list[Rate | None]) -> list[float | None]:
    return [None if report is None else round(report.rate, 6) for report in reports]


def test_hz_measures_a_publisher_that_stops_and_resumes_afresh() -> None:
    clock = FakeClock()
    window = RateWindow(clock)
    assert rates(publish(window, clock, 10, 3)) == [10.0, 10.0, 10.0]
    silence = publish(window, clock, 0, 3)
    assert silence == [None, None, None]  # not the old 10 Hz, again and again
    assert [hz_line(report) for report in silence] == ["no new messages"] * 3
    resumed = publish(window, clock, 2, 3)
    assert rates(resumed) == [2.0, 2.0, 2.0]  # not a mix of the 10 Hz and the gap
    assert resumed[0] is not None and resumed[0].count == 2 and resumed[0].max_gap == 0.5


def test_hz_does_not_mix_a_lone_message_long_ago_into_a_new_rate() -> None:
    clock = FakeClock()
    window = RateWindow(clock)
    assert publish(window, clock, 1, 1) == [None]  # one message: no rate yet
    assert publish(window, clock, 0, 30) == [None] * 30
    assert rates(publish(window, clock, 4, 2)) == [4.0, 4.0]


def test_hz_still_measures_a_topic_slower_than_the_report_period() -> None:
    clock = FakeClock()
    window = RateWindow(clock)
    assert rates(publish(window, clock, 0.5, 8)) == [None, None, None, 0.5, None, 0.5, None, 0.5]


def test_hz_window_keeps_the_latest_arrivals() -> None:
    clock = FakeClock()
    window = RateWindow(clock, size=5)
    publish(window, clock, 10, 2)
    last = publish(window, clock, 5, 1)[-1]
    assert last is not None and last.count == 5 and last.rate == pytest.approx(5.0)


def test_hz_prints_a_rate_the_ros2_way() -> None:
    line = hz_line(Rate(rate=10.0, min_gap=0.09, max_gap=0.11, count=11))
    assert line == "average rate: 10.000\n\tmin: 0.090s max: 0.110s window: 11"
