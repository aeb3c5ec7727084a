"""``cyborg router|node|topic|service|param`` across processes, as a user types them."""

from __future__ import annotations

import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.test_bus_multiprocess import free_port

pytestmark = pytest.mark.heavy
PEER = Path(__file__).with_name("bus_peer.py")


def cyborg(*args: str, timeout: float = 20) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "cyborg", *args], capture_output=True,
                          text=True, timeout=timeout)


@pytest.fixture(scope="module")
def endpoint() -> Iterator[str]:
    address = f"tcp/127.0.0.1:{free_port()}"
    router = subprocess.Popen([sys.executable, "-m", "cyborg", "router", "--listen", address],
                              stdout=subprocess.PIPE, text=True)
    assert router.stdout is not None
    assert "listening on" in router.stdout.readline()
    peers = [subprocess.Popen([sys.executable, str(PEER), role, address], text=True,
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE)
             for role in ("params", "server", "talker")]
    for peer in peers:
        assert peer.stdout is not None and peer.stdout.readline().strip() == "ready"
    yield address
    for peer in peers:
        assert peer.stdin is not None
        peer.stdin.close()
        peer.wait(10)
    router.terminate()
    router.wait(10)


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
    out, _ = listener.communicate(timeout=20)
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
    unknown_topic = on(endpoint, "topic", "echo", "/nothing/here")
    assert unknown_topic.returncode == 1 and "not in the graph" in unknown_topic.stderr


def test_no_router_is_a_clear_error() -> None:
    result = cyborg("node", "list", "--connect", f"tcp/127.0.0.1:{free_port()}", "--wait", "0.2")
    assert result.returncode == 1
    assert "no router reachable" in result.stderr and "cyborg router" in result.stderr
    bad = cyborg("node", "list", "--connect", "localhost:7447")
    assert bad.returncode == 1 and "endpoint 'localhost:7447'" in bad.stderr
