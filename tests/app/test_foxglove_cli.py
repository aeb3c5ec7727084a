"""``cyborg foxglove`` and ``cyborg up --foxglove``: defaults from the component, a whole run."""

from __future__ import annotations

import inspect
import json
import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from cyborg.app.cli import build_parser
from cyborg.app.foxglove_commands import foxglove_description
from cyborg.app.up import up_description
from cyborg.bus import BusConfig, Context
from cyborg.bus.component import LaunchError, NodeSpec
from cyborg.foxglove import component as foxglove
from cyborg.foxglove.server import FoxgloveServer
from tests.foxglove.protocol_client import ProtocolClient
from tests.ports import free_port
from tests.running_system import interruptible


def test_cyborg_foxglove_takes_its_defaults_from_the_component() -> None:
    (spec,) = foxglove_description(build_parser().parse_args(["foxglove"])).nodes
    assert (spec.kind, spec.name, spec.namespace) == ("foxglove", foxglove.NAME,
                                                      foxglove.NAMESPACE)
    assert (spec.parameters["port"], spec.parameters["host"]) == (foxglove.PORT, foxglove.HOST)
    assert foxglove.PORT == 8765 and foxglove.HOST == "127.0.0.1"
    assert inspect.signature(FoxgloveServer).parameters["port"].default == foxglove.PORT
    (wide,) = foxglove_description(build_parser().parse_args(
        ["foxglove", "--host", "0.0.0.0", "--allow-origin", "https://tools.example",
         "--token-file", "/run/token"])).nodes
    assert wide.parameters["allow_origins"] == ["https://tools.example"]
    assert wide.parameters["token_file"] == "/run/token"


def test_cyborg_up_starts_a_foxglove_server_only_when_asked() -> None:
    def kinds(*extra: str) -> dict[str, NodeSpec]:
        args = build_parser().parse_args(["up", "--no-detector", *extra])
        return {spec.kind: spec for spec in up_description(args).nodes}
    assert "foxglove" not in kinds()
    served = kinds("--foxglove")["foxglove"]
    assert served.parameters["port"] == foxglove.PORT
    assert served.parameters["host"] == foxglove.HOST
    assert kinds("--foxglove", "9000")["foxglove"].parameters["port"] == 9000


def test_the_component_declares_its_defaults_and_refuses_a_missing_token_file(
        tmp_path: Path) -> None:
    with Context(BusConfig.isolated()) as context:
        running = foxglove.start(context, NodeSpec("foxglove", foxglove.NAME, foxglove.NAMESPACE,
                                                   {"port": 0}))
        try:
            parameters = running.server.node.parameters
            assert parameters["host"] == foxglove.HOST
            assert parameters["allow_origins"] == list(foxglove.ALLOW_ORIGINS)
            assert f"ws://127.0.0.1:{running.server.port}" in running.describe()
        finally:
            running.stop()
        missing = tmp_path / "token"
        with pytest.raises(LaunchError, match=f"here: token file {missing}: missing"):
            foxglove.start(context, NodeSpec("foxglove", "fox", "/", {
                "port": 0, "token_file": str(missing)}, where="here"))


@pytest.mark.heavy
def test_cyborg_up_with_foxglove_serves_the_robot_map_and_tree() -> None:
    bus_port = free_port()
    process = subprocess.Popen(
        [sys.executable, "-m", "cyborg", "up", "--listen", f"tcp/127.0.0.1:{bus_port}",
         "--no-monitor", "--no-detector", "--foxglove", "0"], stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True, env=dict(os.environ, PYTHONUNBUFFERED="1"),
        preexec_fn=interruptible)
    try:
        assert process.stdout is not None
        port = None
        for _ in range(40):
            found = re.search(r"open ws://127\.0\.0\.1:(\d+)", process.stdout.readline())
            if found:
                port = int(found[1])
                break
        assert port is not None, "cyborg up did not say where Foxglove connects"
        with ProtocolClient(f"ws://127.0.0.1:{port}") as client:
            scene = client.channel("/cyborg/map_scene", timeout=60)
            assert scene["schemaName"] == "foxglove.SceneUpdate"
            assert client.channel("/cyborg/map")["schemaName"] == "nav_msgs/msg/OccupancyGrid"
            pose = client.subscribe("/cyborg/pose")
            tick = client.subscribe("/cyborg/bt/tick")
            message = json.loads(client.payloads(tick, timeout=60)[0])
            decoded = Context(BusConfig.isolated())
            try:
                position = decoded.types.deserialize(client.payloads(pose, timeout=60)[0],
                                                     "geometry_msgs/msg/Pose2D")
            finally:
                decoded.close()
        assert any(node["title"].startswith("MoveTo") for node in message["nodes"])
        assert -1000 < position.x < 1000
    finally:
        process.send_signal(signal.SIGINT)
        _out, err = process.communicate(timeout=60)
    assert process.returncode == 130, err
    assert "Traceback" not in err


def test_a_port_that_is_not_one_is_refused_naming_it() -> None:
    with Context(BusConfig.isolated()) as context, pytest.raises(
            LaunchError, match=re.escape("here: port 70000: expected 0 (any free port) to 65535")):
        foxglove.start(context, NodeSpec("foxglove", "fox", "/", {"port": 70000},
                                         where="here"))
