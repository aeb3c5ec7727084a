"""Each component starts from its own package's component module, and each default is written
once: the commands (`cyborg up`, `sim`, `bt serve`, `monitor`, `detect`) take theirs from the
components and from cyborg.interfaces."""

from __future__ import annotations

import inspect
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from cyborg.app import launchables, up_vision
from cyborg.app.cli import build_parser
from cyborg.app.launchables import KINDS, starter_for
from cyborg.app.monitor_commands import monitor_description
from cyborg.app.up import up_description
from cyborg.bt import TickLoop
from cyborg.bus import BusConfig, Context
from cyborg.bus.component import NodeSpec
from cyborg.interfaces import detector, robot, tree_runner
from cyborg.monitor import component as monitor
from cyborg.monitor.monitor import Monitor
from cyborg.perception import component as perception
from cyborg.robot.settling_robot import SettlingBusRobot
from cyborg.runner import component as runner
from cyborg.runner.tree_runner import TreeRunnerNode
from cyborg.sim import component as sim
from cyborg.sim.battery import Battery
from cyborg.sim.loop import SimulationLoop
from cyborg.vision import component as vision
from cyborg.vision.camera_node import CameraNode
from cyborg.vision.detector import Detector
from tests.builders import N, project_json, tree_json

COMPONENT_MODULES = {"simulator": "cyborg.sim.component",
                     "tree_runner": "cyborg.runner.component",
                     "monitor": "cyborg.monitor.component",
                     "foxglove": "cyborg.foxglove.component",
                     "camera": "cyborg.vision.component",
                     "detector": "cyborg.vision.component",
                     "recorder": "cyborg.record.component",
                     "tracker": "cyborg.perception.component"}


def _default(function: Callable[..., Any], name: str) -> Any:
    return inspect.signature(function).parameters[name].default


# ---------------------------------------------------------------------- the table of kinds
def test_every_kind_starts_from_its_component_module() -> None:
    assert set(KINDS) == set(COMPONENT_MODULES)
    for kind, starter in KINDS.items():
        function = getattr(starter, "func", starter)  # the tree runner's has its robot bound
        assert function.__module__ == COMPONENT_MODULES[kind], kind
        by_name = NodeSpec(f"{function.__module__}:{function.__name__}", kind)
        assert starter_for(by_name) is function, "a launch file may name it as module:function"
    assert KINDS["tree_runner"].keywords == {"robot": SettlingBusRobot}  # type: ignore[attr-defined]


def test_the_launch_code_keeps_only_the_table() -> None:
    own = [name for name, value in vars(launchables).items()
           if (inspect.isfunction(value) or inspect.isclass(value))
           and value.__module__ == launchables.__name__]
    assert own == ["starter_for"]


# ---------------------------------------------------------------------- defaults, written once
def test_cyborg_up_takes_its_defaults_from_the_components() -> None:
    args = build_parser().parse_args(["up", "--no-detector"])
    assert args.monitor_port == monitor.PORT == _default(Monitor, "port")
    assert args.monitor_host == monitor.HOST == _default(Monitor, "host")
    assert args.namespace == sim.NAMESPACE == robot.NAMESPACE
    specs = {spec.kind: spec for spec in up_description(args).nodes}
    assert [specs[kind].name for kind in ("simulator", "tree_runner", "monitor")] == [
        sim.NAME, runner.NAME, monitor.NAME]
    assert specs["monitor"].parameters["port"] == monitor.PORT
    assert specs["monitor"].parameters["trees"] == list(monitor.TREES) == [runner.NAMESPACE]
    assert specs["tree_runner"].namespace == runner.NAMESPACE == tree_runner.NAMESPACE
    assert specs["tree_runner"].parameters["robot_namespace"] == runner.ROBOT_NAMESPACE
    assert specs["simulator"].namespace == specs["monitor"].namespace == sim.NAMESPACE

    moved = {spec.kind: spec for spec in up_description(build_parser().parse_args(
        ["up", "--no-detector", "--namespace", "robot1"])).nodes}
    assert moved["tree_runner"].namespace == "/robot1/bt"
    assert moved["monitor"].parameters["trees"] == ["/robot1/bt"]
    assert moved["tree_runner"].parameters["robot_namespace"] == "/robot1"


def test_only_the_simulated_cameras_people_are_in_the_simulated_robots_way() -> None:
    def specs(*flags: str) -> dict[str, NodeSpec]:
        return {spec.kind: spec for spec in up_description(build_parser().parse_args(
            ["up", *flags])).nodes}
    simulated = specs()
    assert simulated["simulator"].parameters["avoid_objects"] is True
    assert simulated["simulator"].parameters["camera"] is True
    assert simulated["tracker"].parameters["use_sim_time"] is True  # it stamps as the sim does
    assert "detector" not in simulated and "camera" not in simulated
    # a recorded video's people are not in the simulated world
    assert specs("--camera", "real", "--no-detector")["simulator"].parameters[
        "avoid_objects"] is False


def test_cyborg_up_wires_the_camera_to_the_detector_by_the_contract(
        monkeypatch: pytest.MonkeyPatch) -> None:
    args = build_parser().parse_args(["up", "--camera", "real"])
    assert args.model == vision.MODEL
    monkeypatch.setattr(up_vision, "model_for_up", lambda name: Path(f"/models/{name}.onnx"))
    camera, found, tracker = up_vision.vision_nodes(args, robot.NAMESPACE)
    assert (camera.name, camera.namespace) == (vision.CAMERA_NAME, detector.CAMERA_NAMESPACE)
    assert (found.name, found.namespace) == (vision.DETECTOR_NAME, detector.DETECTOR_NAMESPACE)
    assert found.parameters["image_topic"] == detector.DEFAULT_IMAGE_TOPIC
    assert found.parameters["depth_topic"] == detector.DEFAULT_DEPTH_TOPIC
    assert (tracker.kind, tracker.name, tracker.namespace) == (
        "tracker", perception.TRACKER_NAME, robot.NAMESPACE)
    moved = up_vision.vision_nodes(args, "/robot1")
    assert [spec.namespace for spec in moved] == ["/robot1/camera", "/robot1/detector",
                                                  "/robot1"]
    assert moved[1].parameters["image_topic"] == "/robot1/camera/left/image_raw"


def test_the_commands_take_their_defaults_from_the_components() -> None:
    parser = build_parser()
    serve = parser.parse_args(["bt", "serve", "tree.json"])
    assert serve.rate == runner.RATE == _default(TickLoop, "rate_hz") \
        == _default(TreeRunnerNode, "rate_hz")
    assert parser.parse_args(["bt", "run", "tree.json"]).rate == runner.RATE
    assert (serve.namespace, serve.robot_namespace) == (runner.NAMESPACE, runner.ROBOT_NAMESPACE)
    assert parser.parse_args(["bt", "enable"]).namespace == runner.NAMESPACE

    (spec,) = monitor_description(parser.parse_args(["monitor"])).nodes
    assert (spec.name, spec.namespace) == (monitor.NAME, monitor.NAMESPACE)
    assert spec.parameters["port"] == monitor.PORT and spec.parameters["host"] == monitor.HOST
    assert spec.parameters["trees"] == list(monitor.TREES)

    simulated = parser.parse_args(["sim", "--map", "campus.map"])
    assert simulated.speed == sim.SPEED == _default(SimulationLoop, "speed")
    assert simulated.namespace == sim.NAMESPACE
    assert Battery().charge_percent == sim.BATTERY

    detect = parser.parse_args(["detect", "photo.jpg"])
    assert detect.model == vision.MODEL
    for option, keyword in (("confidence", "confidence"), ("iou", "iou"),
                            ("backend", "backend")):
        assert getattr(detect, option) == _default(Detector.open, keyword)
    assert (detect.confidence, detect.iou) == (_default(Detector, "confidence"),
                                              _default(Detector, "iou"))
    assert _default(CameraNode, "rate") == vision.CAMERA_RATE


def test_the_components_declare_those_defaults(tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    tree = tmp_path / "tree.b3.json"
    tree.write_text(project_json([tree_json(N("Succeeder", id="s"))]))
    monkeypatch.setattr(Monitor, "start", lambda self, timeout=10.0: None)  # binds no port
    with Context(BusConfig.isolated()) as context:
        bare = runner.start(context, NodeSpec("tree_runner", runner.NAME, runner.NAMESPACE,
                                              {"tree_file": str(tree)}))  # no robot given
        try:
            assert bare.runner.runner.rate_hz == runner.RATE
            assert bare.robot is None and bare.robot_node is None, "no robot unless given"
        finally:
            bare.stop()
        spec = NodeSpec("tree_runner", runner.NAME, runner.NAMESPACE, {"tree_file": str(tree)})
        wired = starter_for(spec)(context, spec)
        try:
            assert isinstance(wired, runner.RunningTree)
            assert isinstance(wired.robot, SettlingBusRobot)
            assert wired.robot.namespace == runner.ROBOT_NAMESPACE
        finally:
            wired.stop()
        watching = monitor.start(context, NodeSpec("monitor", monitor.NAME, monitor.NAMESPACE))
        try:
            assert (watching.monitor.host, watching.monitor.requested_port) == (monitor.HOST,
                                                                              monitor.PORT)
            assert sorted(watching.monitor.hub.sources) == list(monitor.TREES)
        finally:
            watching.stop()


def test_a_namespace_moves_under_another_robot() -> None:
    from cyborg.app.launch import under_robot
    assert under_robot("/cyborg", tree_runner.NAMESPACE) == tree_runner.NAMESPACE
    assert under_robot("robot1/", detector.CAMERA_NAMESPACE) == "/robot1/camera"
    assert under_robot("/", tree_runner.NAMESPACE) == "/bt"
    assert under_robot("/", robot.NAMESPACE) == "/"
    with pytest.raises(ValueError, match="not under"):
        under_robot("/robot1", "/elsewhere/bt")

