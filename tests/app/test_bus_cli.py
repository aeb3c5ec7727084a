"""``cyborg router|node|topic|service|param`` across processes, as a user types them."""

from __future__ import annotations

import subprocess
import sys
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, Any

import pytest

from cyborg.bus import MessageTypes
from tests.ports import free_port

pytestmark = pytest.mark.heavy
PEER = Path(__file__).resolve().parents[1] / "bus" / "bus_peer.py"


COMMAND_LIMIT = 90.0
"""Wall seconds a command may take: each starts a Python process that imports the bus and the
command's modules, seconds on a busy 2-core machine; a hung command still fails."""


def cyborg(*args: str, timeout: float = COMMAND_LIMIT) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "cyborg", *args], capture_output=True,
                          text=True, timeout=timeout)


def first_line(stream: IO[str] | None, timeout: float) -> str:
    """The next line of a child's output, or "" if none comes within ``timeout`` seconds."""
    assert stream is not None
    lines: list[str] = []
    reader = threading.Thread(target=lambda: lines.append(stream.readline()), daemon=True)
    reader.start()
    reader.join(timeout)
    return lines[0] if lines else ""


def rest(process: subprocess.Popen[str]) -> str:
    """What a child that has ended wrote to stderr (for a failing assertion's message)."""
    if process.poll() is None or process.stderr is None:
        return "(still running)"
    return process.stderr.read()


def start_router() -> tuple[str, subprocess.Popen[str]]:
    address = f"tcp/127.0.0.1:{free_port()}"
    router = subprocess.Popen([sys.executable, "-m", "cyborg", "router", "--listen", address],
                              stdout=subprocess.PIPE, text=True)
    assert "listening on" in first_line(router.stdout, 20)
    return address, router


def start_peer(role: str, address: str) -> subprocess.Popen[str]:
    """A ``bus_peer.py`` process; it lives until its stdin closes (see :func:`stop`)."""
    peer = subprocess.Popen([sys.executable, str(PEER), role, address], text=True,
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE)
    assert first_line(peer.stdout, 20).strip() == "ready", f"peer {role} did not start"
    return peer


def stop(process: subprocess.Popen[str]) -> None:
    if process.stdin is not None:
        process.stdin.close()
    else:
        process.terminate()
    try:
        process.wait(10)
    except subprocess.TimeoutExpired:
        process.kill()
        raise


@pytest.fixture(scope="module")
def endpoint() -> Iterator[str]:
    address, router = start_router()
    peers = [start_peer(role, address) for role in ("params", "server", "talker")]
    yield address
    for process in [*peers, router]:
        stop(process)


@pytest.fixture
def fresh_endpoint() -> Iterator[str]:
    """A router of the test's own, for tests that need a topic or service to appear late."""
    address, router = start_router()
    yield address
    stop(router)


@pytest.fixture
def peers() -> Iterator[Callable[[str, str], subprocess.Popen[str]]]:
    """Start ``bus_peer.py`` roles during a test; they are stopped after it."""
    started: list[subprocess.Popen[str]] = []

    def start(role: str, address: str) -> subprocess.Popen[str]:
        started.append(start_peer(role, address))
        return started[-1]
    yield start
    for peer in started:
        stop(peer)


def background(*args: str) -> subprocess.Popen[str]:
    """A ``cyborg`` command left running, its stdout and stderr piped."""
    return subprocess.Popen([sys.executable, "-m", "cyborg", *args], text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)


def on(endpoint: str, *args: str) -> subprocess.CompletedProcess[str]:
    return cyborg(*args, "--connect", endpoint, "--wait", "0.5")


def test_node_and_topic_lists(endpoint: str) -> None:
    nodes = on(endpoint, "node", "list")
    assert nodes.returncode == 0, nodes.stderr
    assert {"/robot/peer_params", "/robot/peer_server", "/robot/peer_talker"} <= set(
        nodes.stdout.split())
    topics = on(endpoint, "topic", "list", "-t")
    assert "/robot/chatter [std_msgs/msg/String]" in topics.stdout.splitlines()
    services = on(endpoint, "service", "list", "-t")
    assert "/robot/add [example_interfaces/srv/AddTwoInts]" in services.stdout.splitlines()
    info = on(endpoint, "node", "info", "/robot/peer_talker")
    assert "    /robot/chatter: std_msgs/msg/String" in info.stdout


def test_echo_pub_and_hz(endpoint: str) -> None:
    echo = on(endpoint, "topic", "echo", "/robot/chatter", "--count", "2")
    assert echo.returncode == 0, echo.stderr
    assert echo.stdout.count("---") == 2 and "data: hello" in echo.stdout
    listener = subprocess.Popen(
        [sys.executable, "-m", "cyborg", "topic", "echo", "/note", "std_msgs/msg/String",
         "--once", "--timeout", "15", "--connect", endpoint, "--wait", "0.5"],
        stdout=subprocess.PIPE, text=True)
    threading.Event().wait(2.5)
    published = on(endpoint, "topic", "pub", "/note", "std_msgs/msg/String", "{data: hi there}",
                   "--times", "3", "--rate", "5")
    assert published.returncode == 0, published.stderr
    out, _ = listener.communicate(timeout=COMMAND_LIMIT)
    assert listener.returncode == 0 and "data: hi there" in out
    hz = on(endpoint, "topic", "hz", "/robot/chatter", "--duration", "2")
    rates = [float(line.split()[-1]) for line in hz.stdout.splitlines()
             if line.startswith("average rate")]
    assert rates and 20 < rates[-1] < 70  # the talker sends every 20 ms


def test_service_call(endpoint: str) -> None:
    called = on(endpoint, "service", "call", "/robot/add", "{a: 2, b: 40}")
    assert called.returncode == 0, called.stderr
    assert "sum: 42" in called.stdout
    failed = on(endpoint, "service", "call", "/robot/fail",
                "example_interfaces/srv/AddTwoInts", "{a: 1, b: 2}")
    assert failed.returncode == 1 and "ValueError: cannot add 1 and 2" in failed.stderr
    wrong = on(endpoint, "service", "call", "/robot/add", "{c: 1}")
    assert wrong.returncode == 1 and "c: example_interfaces/srv/AddTwoInts_Request has no" \
        in wrong.stderr


def test_param_list_get_set(endpoint: str) -> None:
    listed = on(endpoint, "param", "list", "/robot/peer_params")
    assert listed.stdout.split() == ["classes", "confidence_threshold"]
    assert on(endpoint, "param", "set", "/robot/peer_params", "confidence_threshold",
              "0.25").returncode == 0
    assert on(endpoint, "param", "get", "/robot/peer_params",
              "confidence_threshold").stdout.strip() == "0.25"
    refused = on(endpoint, "param", "set", "/robot/peer_params", "confidence_threshold", "2")
    assert refused.returncode == 1 and "outside [0, 1]" in refused.stderr
    missing = on(endpoint, "param", "get", "/robot/nobody", "x")
    assert missing.returncode == 1 and "no node '/robot/nobody'" in missing.stderr


def test_bad_input_is_named(endpoint: str) -> None:
    bad_yaml = on(endpoint, "topic", "pub", "/x", "std_msgs/msg/String", "{data: [", "--once")
    assert bad_yaml.returncode == 1 and "are not YAML" in bad_yaml.stderr
    bad_type = on(endpoint, "topic", "pub", "/x", "std_msgs/msg/Nope", "{}", "--once")
    assert bad_type.returncode == 1 and "unknown type 'std_msgs/msg/Nope'" in bad_type.stderr
    unknown_topic = on(endpoint, "topic", "echo", "/nothing/here", "--timeout", "1")
    assert unknown_topic.returncode == 1
    assert "waiting for a publisher of /nothing/here" in unknown_topic.stderr
    assert "no publisher of /nothing/here appeared within 1 s" in unknown_topic.stderr
    no_rate = on(endpoint, "topic", "hz", "/nothing/here", "--duration", "1")
    assert no_rate.returncode == 1 and "appeared within 1 s" in no_rate.stderr
    no_service = on(endpoint, "service", "call", "/nobody/add", "{a: 1}", "--timeout", "1")
    assert no_service.returncode == 1
    assert "waiting for service /nobody/add to become available" in no_service.stderr
    assert "no server of /nobody/add appeared within 1 s" in no_service.stderr


def test_echo_prints_the_latched_message_without_a_flag(endpoint: str, peers: Any) -> None:
    peers("latched", endpoint)
    for flags in ([], ["--latched"]):
        echo = on(endpoint, "topic", "echo", "/robot/status", "--once", "--timeout", "10",
                  *flags)
        assert echo.returncode == 0, echo.stderr
        assert echo.stdout == "data: latest\n---\n"


def test_echo_waits_for_a_publisher_to_learn_the_type(endpoint: str) -> None:
    echo = background("topic", "echo", "/late/battery", "--once", "--timeout", "20",
                      "--connect", endpoint, "--wait", "0.5")
    waiting = first_line(echo.stderr, 20)
    assert "waiting for a publisher of /late/battery to learn its type" in waiting, rest(echo)
    assert "cyborg topic echo /late/battery TYPE" in waiting
    published = on(endpoint, "topic", "pub", "/late/battery", "sensor_msgs/msg/BatteryState",
                   "{percentage: 0.5, power_supply_status: 2}", "--times", "30", "--rate", "10")
    assert published.returncode == 0, published.stderr
    out, err = echo.communicate(timeout=COMMAND_LIMIT)
    assert echo.returncode == 0, err
    fields = [line.split(":")[0] for line in out.splitlines() if not line.startswith(" ")]
    battery = MessageTypes().store.fielddefs["sensor_msgs/msg/BatteryState"][1]
    assert fields == [*(name for name, _ in battery), "---"]
    assert "percentage: 0.5" in out and "power_supply_status: 2" in out
    assert "POWER_SUPPLY" not in out  # the message's constants are not fields
    assert "POWER_SUPPLY" not in published.stdout


def test_a_late_latched_publisher_reaches_a_waiting_echo(fresh_endpoint: str,
                                                          peers: Any) -> None:
    echo = background("topic", "echo", "/robot/status", "--once", "--timeout", "20",
                      "--connect", fresh_endpoint, "--wait", "0.5")
    assert "waiting for a publisher" in first_line(echo.stderr, 20), rest(echo)
    peers("latched", fresh_endpoint)
    out, err = echo.communicate(timeout=COMMAND_LIMIT)
    assert echo.returncode == 0, err
    # "first" may arrive live (the peer publishes it as it starts), "latest" from history
    assert out in ("data: first\n---\n", "data: latest\n---\n")


def test_an_echo_given_the_type_hears_a_late_latched_publisher(fresh_endpoint: str,
                                                                peers: Any) -> None:
    echo = background("topic", "echo", "/robot/status", "std_msgs/msg/String", "--once",
                      "--timeout", "20", "--connect", fresh_endpoint, "--wait", "0.5")
    threading.Event().wait(3.0)  # it has subscribed by now, before any publisher
    peers("latched", fresh_endpoint)
    out, err = echo.communicate(timeout=COMMAND_LIMIT)
    assert echo.returncode == 0, err
    assert out in ("data: first\n---\n", "data: latest\n---\n")


def test_service_call_waits_for_its_server(fresh_endpoint: str, peers: Any) -> None:
    calls = [background("service", "call", "/robot/add", *typed, "{a: 2, b: 40}", "--timeout",
                        "20", "--connect", fresh_endpoint, "--wait", "0.5")
             for typed in ([], ["example_interfaces/srv/AddTwoInts"])]
    for call in calls:
        assert "waiting for service /robot/add to become available" in first_line(
            call.stderr, 20), rest(call)
    peers("server", fresh_endpoint)
    for call in calls:
        out, err = call.communicate(timeout=COMMAND_LIMIT)
        assert call.returncode == 0, err
        assert "sum: 42" in out


def test_no_router_is_a_clear_error() -> None:
    result = cyborg("node", "list", "--connect", f"tcp/127.0.0.1:{free_port()}", "--wait", "0.2")
    assert result.returncode == 1
    assert "no router reachable" in result.stderr and "cyborg router" in result.stderr
    bad = cyborg("node", "list", "--connect", "localhost:7447")
    assert bad.returncode == 1 and "endpoint 'localhost:7447'" in bad.stderr
