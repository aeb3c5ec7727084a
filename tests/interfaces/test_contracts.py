"""The contracts of :mod:`cyborg.interfaces`: server and client sides use the same names, types
and QoS (checked on a live, isolated bus through its graph), and the constants in the contracts
are the message definitions' own."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Iterator
from enum import Enum
from pathlib import Path

import pytest

from cyborg.bt import HookMode, Status
from cyborg.bus import BusConfig, Context, MessageTypes, Node, Qos
from cyborg.bus.component import NodeSpec
from cyborg.bus.graph import Graph, GraphEntity
from cyborg.bus.wire import Durability, EntityKind
from cyborg.interfaces import detector, modes, perception, player, robot, simulation, tree_runner
from cyborg.interfaces.contract import Action, Service, Topic, resolve
from cyborg.interfaces.help import HELP
from cyborg.monitor.monitor import Monitor
from cyborg.monitor.player_source import PlayerSource
from cyborg.monitor.robot_clients import RobotClients
from cyborg.monitor.source import TreeSource
from cyborg.nav.arnl_map import read_map
from cyborg.perception import component as tracker_component
from cyborg.record.mcap_file import McapFile
from cyborg.record.playback_source import open_recording
from cyborg.record.player import Player
from cyborg.robot.bus_robot import BusRobot
from cyborg.runner.tree_runner import TreeRunnerNode
from cyborg.sim import component as sim_component
from cyborg.sim.loop import SimulationLoop
from cyborg.sim.node import SimulatorNode
from cyborg.sim.object_feed import ObjectFeed
from cyborg.sim.people_and_camera import CAMERA_NAME
from cyborg.sim.simulator import Simulator
from cyborg.vision import CameraNode, CameraTopics, DetectionPipeline, Detector, DetectorNode
from cyborg.vision.samples import SampleSource
from tests.conftest import shared_dir
from tests.running_system import write_tree
from tests.small_maps import room_map

SERVING = (EntityKind.PUBLISHER, EntityKind.SERVICE_SERVER)
USING = (EntityKind.SUBSCRIPTION, EntityKind.SERVICE_CLIENT)
PARTNER = {EntityKind.SUBSCRIPTION: EntityKind.PUBLISHER,
           EntityKind.SERVICE_CLIENT: EntityKind.SERVICE_SERVER}


@pytest.fixture
def bus() -> Iterator[Context]:
    with Context(BusConfig.isolated()) as context:
        yield context


def endpoints(graph: Graph, node_name: str, kinds: Iterable[EntityKind]) -> list[GraphEntity]:
    """The endpoints of one node, without the parameter services every node has (those are
    the bus's own, not a contract's)."""
    return [entity for entity in graph.entities(kinds) if entity.node_name == node_name
            and "rcl_interfaces/srv/" not in entity.type_name]


def settle(graph: Graph, ready: Callable[[], bool]) -> None:
    assert graph.wait_for(lambda _graph: ready(), 10.0), "the graph did not settle"
    time.sleep(0.05)  # tokens of one node arrive together; a moment more costs nothing


def assert_client_is_served(graph: Graph, client: str, server: str) -> set[str]:
    """Every subscription and service client of node ``client`` has a publisher or server of
    the same name and type on node ``server``, and subscribes latched exactly where the topic
    is published latched (else it would miss, or wait in vain for, the last message); returns
    the names the client uses."""
    used = endpoints(graph, client, USING)
    assert used, f"{client} uses nothing"
    offered = {(entity.kind, entity.topic, entity.type_name): entity
               for entity in endpoints(graph, server, SERVING)}
    for entity in used:
        partner = offered.get((PARTNER[entity.kind], entity.topic, entity.type_name))
        assert partner is not None, (f"{client} uses {entity.topic} ({entity.type_name}), which "
                                     f"{server} does not offer")
        if entity.kind is EntityKind.SUBSCRIPTION:
            assert entity.latched == partner.latched, f"{entity.topic}: durability differs"
    return {entity.topic for entity in used}


def contract_names(namespace: str, topics: Iterable[Topic], services: Iterable[Service],
                   actions: Iterable[Action] = ()) -> set[str]:
    names = {topic.full_name(namespace) for topic in topics}
    names |= {service.full_name(namespace) for service in services}
    for action in actions:
        base = action.full_name(namespace) + "/_action/"
        names |= {base + part for part in ("send_goal", "get_result", "cancel_goal", "feedback",
                                           "status")}
    return names


def assert_serves(graph: Graph, server: str, namespace: str, topics: Iterable[Topic],
                  services: Iterable[Service] = ()) -> None:
    """Node ``server`` offers each of ``topics`` and ``services`` as the contract says."""
    offered = {(entity.topic, entity.type_name): entity
               for entity in endpoints(graph, server, SERVING)}
    for topic in topics:
        entity = offered.get((topic.full_name(namespace), topic.type_name))
        assert entity is not None, f"{server} does not publish {topic}"
        assert entity.kind is EntityKind.PUBLISHER and entity.latched == topic.latched, topic
    for service in services:
        entity = offered.get((service.full_name(namespace), service.type_name))
        assert entity is not None and entity.kind is EntityKind.SERVICE_SERVER, \
            f"{server} does not serve {service}"


def assert_subscribes(graph: Graph, node_name: str, namespace: str,
                      topics: Iterable[Topic]) -> None:
    """Node ``node_name`` subscribes to each of ``topics`` as the contract says."""
    used = {(entity.topic, entity.type_name): entity
            for entity in endpoints(graph, node_name, [EntityKind.SUBSCRIPTION])}
    for topic in topics:
        entity = used.get((topic.full_name(namespace), topic.type_name))
        assert entity is not None, f"{node_name} does not subscribe to {topic}"
        assert entity.latched == topic.latched, topic


# ---------------------------------------------------------------------- the robot
BUS_ROBOT_ENDPOINTS = 13
"""pose and battery_status, six services, and move_to_goal's three services and two topics."""

def test_the_simulator_serves_everything_bus_robot_uses(bus: Context, shared: Path) -> None:
    sim = Simulator(read_map(shared / "maps" / "AMROffice.map"), start="Dock")
    SimulatorNode(Node("arnl", robot.NAMESPACE, context=bus), SimulationLoop(sim))
    BusRobot(Node("bt", robot.NAMESPACE, context=bus))  # the default namespace: the contract's
    graph = bus.graph
    contract = contract_names(robot.NAMESPACE, robot.TOPICS, robot.SERVICES, [robot.MOVE_TO_GOAL])
    settle(graph, lambda: len(endpoints(graph, "/cyborg/bt", USING)) >= BUS_ROBOT_ENDPOINTS
           and len(endpoints(graph, "/cyborg/arnl", SERVING)) >= len(contract)
           and len(endpoints(graph, "/cyborg/arnl", [EntityKind.SUBSCRIPTION]))
           >= len(robot.COMMANDS))

    used = assert_client_is_served(graph, "/cyborg/bt", "/cyborg/arnl")
    assert used <= contract
    assert robot.MOVE_TO_GOAL.full_name(robot.NAMESPACE) + "/_action/send_goal" in used
    assert_serves(graph, "/cyborg/arnl", robot.NAMESPACE, robot.TOPICS, robot.SERVICES)
    served = {entity.topic for entity in endpoints(graph, "/cyborg/arnl", SERVING)}
    assert served == contract, "the simulator serves something its contract does not name"
    assert_subscribes(graph, "/cyborg/arnl", robot.NAMESPACE, robot.COMMANDS)
    commands = {topic.full_name(robot.NAMESPACE) for topic in robot.COMMANDS}
    assert commands == {"/cyborg/cmd_vel", "/initialpose"}


def test_bus_robot_follows_the_robot_under_another_namespace(bus: Context, shared: Path) -> None:
    sim = Simulator(read_map(shared / "maps" / "AMROffice.map"), start="Dock")
    SimulatorNode(Node("arnl", "/robot2", context=bus), SimulationLoop(sim))
    BusRobot(Node("bt", "/elsewhere", context=bus), "/robot2")
    graph = bus.graph
    settle(graph, lambda: len(endpoints(graph, "/elsewhere/bt", USING)) >= BUS_ROBOT_ENDPOINTS
           and len(endpoints(graph, "/robot2/arnl", SERVING)) >= len(
               contract_names("/robot2", robot.TOPICS, robot.SERVICES, [robot.MOVE_TO_GOAL])))
    used = assert_client_is_served(graph, "/elsewhere/bt", "/robot2/arnl")
    assert all(name.startswith("/robot2/") for name in used)


MONITOR_ROBOT_ENDPOINTS = 10
"""stop, dock, undock, set_pose, nav/get_available_goals, and move_to_goal's three services and
two topics."""


def test_the_simulator_serves_everything_the_monitor_acts_with(bus: Context,
                                                               shared: Path) -> None:
    sim = Simulator(read_map(shared / "maps" / "AMROffice.map"), start="Dock")
    SimulatorNode(Node("arnl", "/robot2", context=bus), SimulationLoop(sim))
    RobotClients(Node("monitor", "/cyborg", context=bus), "/robot2")
    graph = bus.graph
    contract = contract_names("/robot2", robot.TOPICS, robot.SERVICES, [robot.MOVE_TO_GOAL])
    settle(graph, lambda: len(endpoints(graph, "/cyborg/monitor", USING))
           >= MONITOR_ROBOT_ENDPOINTS
           and len(endpoints(graph, "/robot2/arnl", SERVING)) >= len(contract))
    used = assert_client_is_served(graph, "/cyborg/monitor", "/robot2/arnl")
    assert used <= contract and all(name.startswith("/robot2/") for name in used)
    assert robot.SET_POSE.full_name("/robot2") in used
    published = {(entity.topic, entity.type_name)
                 for entity in endpoints(graph, "/cyborg/monitor", [EntityKind.PUBLISHER])}
    assert published == {(robot.CMD_VEL.full_name("/robot2"), robot.CMD_VEL.type_name)}
    assert_subscribes(graph, "/robot2/arnl", "/robot2", [robot.CMD_VEL])


# ---------------------------------------------------------------------- the tree runner
def test_the_tree_runner_serves_everything_the_monitor_uses(bus: Context, tmp_path: Path) -> None:
    tree = write_tree(tmp_path, {"name": "Succeeder"})
    runner = TreeRunnerNode(Node("tree_runner", tree_runner.NAMESPACE, context=bus), tree)
    source = TreeSource(Node("monitor", "/cyborg", context=bus), tree_runner.NAMESPACE,
                        lambda _namespace, _what: None)
    graph = bus.graph
    try:
        settle(graph, lambda: source.alive and len(endpoints(graph, "/cyborg/monitor", USING))
               >= len(tree_runner.TOPICS) + len(tree_runner.SERVICES) - 1)
        used = assert_client_is_served(graph, "/cyborg/monitor", "/cyborg/bt/tree_runner")
        assert used <= contract_names(tree_runner.NAMESPACE, tree_runner.TOPICS,
                                      tree_runner.SERVICES)
        assert {topic.full_name(tree_runner.NAMESPACE) for topic in tree_runner.TOPICS} <= used
        assert_serves(graph, "/cyborg/bt/tree_runner", tree_runner.NAMESPACE, tree_runner.TOPICS,
                      tree_runner.SERVICES)
        served = {entity.topic for entity in endpoints(graph, "/cyborg/bt/tree_runner", SERVING)}
        assert served == contract_names(tree_runner.NAMESPACE, tree_runner.TOPICS,
                                        tree_runner.SERVICES)
        monitor = Monitor(Node("monitor2", "/cyborg", context=bus))  # never started: no port
        assert tree_runner.NAMESPACE in monitor.discover()
        assert monitor.hub.default_namespace == tree_runner.NAMESPACE
    finally:
        source.destroy()
        runner.destroy()


def test_a_runner_is_recognised_by_its_structure_topic() -> None:
    structure = tree_runner.STRUCTURE
    assert tree_runner.runner_namespace("/cyborg/bt/behavior_tree", structure.type_name) == \
        "/cyborg/bt"
    assert tree_runner.runner_namespace("/behavior_tree", structure.type_name) == "/"
    assert tree_runner.runner_namespace("/cyborg/bt/behavior_tree", "std_msgs/msg/String") is None
    assert tree_runner.runner_namespace("/cyborg/bt/status", structure.type_name) is None


# ---------------------------------------------------------------------- camera and detector
def test_the_camera_serves_everything_the_detector_uses(bus: Context) -> None:
    camera = CameraNode(Node("camera", detector.CAMERA_NAMESPACE, context=bus),
                        lambda: SampleSource("motorcycle"), rate=20.0)
    model = shared_dir() / "models" / "yolox_nano.onnx"
    topics = CameraTopics(detector.DEFAULT_IMAGE_TOPIC, detector.DEFAULT_DEPTH_TOPIC)
    DetectorNode(Node("detector", detector.DETECTOR_NAMESPACE, context=bus),
                 DetectionPipeline(Detector.open(model, threads=1)), topics)
    camera.start()
    graph = bus.graph
    try:
        # image, right and depth: the last two are advertised with the first frame
        settle(graph, lambda: len(endpoints(graph, "/cyborg/camera/camera", SERVING)) >= 3
               and len(endpoints(graph, "/cyborg/detector/detector", USING)) >= 2)
        used = assert_client_is_served(graph, "/cyborg/detector/detector",
                                       "/cyborg/camera/camera")
        assert used == {detector.IMAGE.full_name(detector.CAMERA_NAMESPACE),
                        detector.DEPTH.full_name(detector.CAMERA_NAMESPACE)}
        assert_serves(graph, "/cyborg/detector/detector", detector.DETECTOR_NAMESPACE,
                      detector.DETECTOR_TOPICS)
    finally:
        camera.stop()


def test_the_simulated_camera_serves_the_detectors_topics_and_the_simulator_its_people(
        bus: Context, tmp_path: Path) -> None:
    """Under the robot's detector namespace, exactly where the detector would; people too."""
    path = tmp_path / "room.map"
    path.write_text(room_map(['RobotHome 1000 1500 0 "" ICON "home"',
                              'Goal 4000 1500 0 "" ICON "spot"']))
    running = sim_component.start(bus, NodeSpec("simulator", "arnl", robot.NAMESPACE, {
        "map": str(path), "camera": True, "people": 1}))
    graph = bus.graph
    camera = f"{detector.DETECTOR_NAMESPACE}/{CAMERA_NAME}"
    try:
        settle(graph, lambda: len(endpoints(graph, camera, SERVING)) >= 3)
        assert detector.detector_of_robot(robot.NAMESPACE) == detector.DETECTOR_NAMESPACE
        assert_serves(graph, camera, detector.DETECTOR_NAMESPACE, detector.DETECTOR_TOPICS)
        assert_serves(graph, f"{robot.NAMESPACE}/arnl", robot.NAMESPACE, simulation.TOPICS)
    finally:
        running.stop()


# ---------------------------------------------------------------------- the descriptors
def test_the_player_serves_its_state_and_services_under_its_namespace_to_the_monitor(
        bus: Context, tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    recording_file = McapFile(path, bus.types)
    channel = recording_file.channel("/chatter", "std_msgs/msg/String", [])
    recording_file.write(channel, 1_000, 1_000, bytes(bus.types.serialize(
        bus.types.message_class("std_msgs/msg/String")(data="x"), "std_msgs/msg/String")))
    recording_file.close()
    recording = open_recording(path, bus.types)
    playing = Player(Node(player.NAME, "/replay", context=bus), recording, paused=True)
    try:
        names = contract_names("/replay", player.TOPICS, player.SERVICES)
        node = f"/replay/{player.NAME}"
        settle(bus.graph, lambda: names <= {e.topic for e in endpoints(bus.graph, node, SERVING)})
        assert_serves(bus.graph, node, "/replay", player.TOPICS, player.SERVICES)
        assert names == {"/replay/player/state", "/replay/player/pause", "/replay/player/seek",
                         "/replay/player/step"}
        found = [player.player_namespace(e.topic, e.type_name)
                 for e in endpoints(bus.graph, node, SERVING)]
        assert [name for name in found if name is not None] == ["/replay"]
        timeline = PlayerSource(Node("monitor", "/cyborg", context=bus), "/replay", lambda: None)
        settle(bus.graph, lambda: len(endpoints(bus.graph, "/cyborg/monitor", USING)) >= 4)
        assert assert_client_is_served(bus.graph, "/cyborg/monitor", node) == names
        timeline.destroy()
    finally:
        playing.close()
        recording.close()


def test_a_runner_of_a_mode_file_serves_the_modes_contract(bus: Context,
                                                            tmp_path: Path) -> None:
    write_tree(tmp_path, {"name": "Runner"}, "mission.b3.json")
    (tmp_path / "mission.modes.toml").write_text(
        'project = "mission.b3.json"\ninitial = "only"\n[modes.only]\ntree = "Test tree"\n')
    runner = TreeRunnerNode(Node("tree_runner", "/cyborg/bt", context=bus),
                            tmp_path / "mission.modes.toml", enabled=False)
    try:
        offered = (modes.STATE, modes.TRANSITIONS)
        names = contract_names("/cyborg/bt", offered, modes.SERVICES)
        node = "/cyborg/bt/tree_runner"
        settle(bus.graph, lambda: names <= {e.topic for e in endpoints(bus.graph, node, SERVING)})
        assert_serves(bus.graph, node, "/cyborg/bt", offered, modes.SERVICES)
        assert_subscribes(bus.graph, node, "/cyborg/bt", [modes.EVENTS])
        assert names == {"/cyborg/bt/mode", "/cyborg/bt/mode/transitions",
                         "/cyborg/bt/mode/set"}
    finally:
        runner.destroy()


def test_names_resolve_as_the_bus_resolves_them() -> None:
    pose = robot.POSE
    assert pose.full_name("/cyborg") == pose.full_name("cyborg/") == "/cyborg/pose"
    assert pose.full_name("/") == pose.full_name("") == "/pose"
    assert robot.CLOCK.full_name("/cyborg") == "/clock"
    assert robot.TF_STATIC.full_name("/robot2") == "/tf_static"  # one tree of frames, as in ROS
    assert robot.INITIAL_POSE.full_name("/robot2") == "/initialpose"  # where RViz publishes it
    assert robot.CMD_VEL.full_name("/robot2") == "/robot2/cmd_vel"
    assert robot.MAP_GEOMETRY.full_name("/robot2") == "/robot2/map_geometry"
    assert resolve("/a/b", "c/d") == "/a/b/c/d"
    assert detector.DEFAULT_IMAGE_TOPIC == "/cyborg/camera/left/image_raw"
    assert detector.IMAGE.remapped("/zed/left").name == "/zed/left"


def test_qos_follows_the_contract() -> None:
    assert robot.BATTERY_STATUS.qos == Qos.latched()
    assert robot.MAP_GEOMETRY.qos == robot.FOOTPRINT.qos == Qos.latched()
    assert robot.TF_STATIC.qos == Qos.latched(100)  # every robot's transforms, at once
    assert robot.POSE.qos == Qos(depth=10)
    assert robot.CMD_VEL.qos == Qos(depth=1)  # only the newest command matters
    assert robot.CURRENT_GOAL.qos == Qos.latched()
    assert detector.IMAGE.qos == Qos(depth=2)
    assert detector.PREDICTIONS.qos.durability is Durability.TRANSIENT_LOCAL
    action, service = robot.MOVE_TO_GOAL, robot.MAKE_PLAN
    assert (action.goal_type, action.result_type, action.feedback_type) == (
        "cyborg_msgs/action/MoveToGoal_Goal", "cyborg_msgs/action/MoveToGoal_Result",
        "cyborg_msgs/action/MoveToGoal_Feedback")
    assert (service.request_type, service.response_type) == (
        "cyborg_msgs/srv/MakePlan_Request", "cyborg_msgs/srv/MakePlan_Response")


def test_every_type_in_the_contracts_is_known() -> None:
    """The classes the descriptors carry are the bus's own, under the names the graph shows."""
    types = MessageTypes()
    for topic in (*robot.TOPICS, *robot.COMMANDS, *tree_runner.TOPICS,
                  *detector.CAMERA_STREAMS.values(), *detector.DETECTOR_TOPICS, *player.TOPICS,
                  *modes.TOPICS, *simulation.TOPICS):
        assert types.message_class(topic.type_name) is topic.message_type, topic
    for service in (*robot.SERVICES, *tree_runner.SERVICES, *player.SERVICES,
                    *modes.SERVICES):
        assert service.type_name in types.services, service
        assert types.message_class(service.request_type) is service.service_type.Request
        assert types.message_class(service.response_type) is service.service_type.Response
    move = robot.MOVE_TO_GOAL
    assert move.type_name in types.actions
    assert [types.message_class(name) for name in (
        move.goal_type, move.result_type, move.feedback_type)] == [
        move.action_type.Goal, move.action_type.Result, move.action_type.Feedback]


# ---------------------------------------------------------------------- constants
TYPES = MessageTypes()


def constants_of(type_name: str, prefix: str = "") -> dict[str, object]:
    """The constants of a generated message class (``prefix`` stripped from their names)."""
    cls = TYPES.message_class(type_name)
    names = [name for name in vars(cls)
             if name.isupper() and not name.startswith("_") and name.startswith(prefix)]
    return {name.removeprefix(prefix): getattr(cls, name) for name in names}


def members(enum: type[Enum]) -> dict[str, object]:
    return {member.name: member.value for member in enum if member.value != ""}


def test_enums_are_the_message_definitions_constants() -> None:
    assert members(robot.MoveOutcome) == constants_of(robot.MOVE_TO_GOAL.result_type)
    battery = robot.BATTERY_STATUS.type_name
    assert members(robot.DockState) == constants_of(battery, "DOCK_")
    assert members(robot.ChargingState) == constants_of(battery, "CHARGING_")
    control = tree_runner.CONTROL.request_type
    assert members(tree_runner.HookAction) == {
        name: value for name, value in constants_of(control).items()
        if name in ("CLEAR", "DISABLE", "FORCE", "BREAKPOINT")}
    assert members(tree_runner.HookStatus) == {
        name: value for name, value in constants_of(control).items()
        if name in ("SUCCESS", "FAILURE", "RUNNING")}
    assert members(modes.ModeAction) == constants_of(modes.SET_MODE.request_type)
    hooks = constants_of(tree_runner.HOOKS.type_name)  # the hooks topic: CLEAR is no hook
    assert hooks == {action.name: action.value for action in tree_runner.HookAction
                     if action is not tree_runner.HookAction.CLEAR}


def test_statuses_and_hook_modes_on_the_bus_are_the_engines() -> None:
    assert constants_of(tree_runner.STATUS.type_name) == {status.name: status.value
                                                         for status in Status}
    for status in tree_runner.HookStatus:
        assert Status(status.value).name == status.name
    assert {mode.value for mode in HookMode} == {
        action.label for action in tree_runner.HookAction
        if action is not tree_runner.HookAction.CLEAR}


def test_constants_change_neither_the_type_hash_nor_the_fields() -> None:
    """The dock states were added to BatteryStatus.msg as constants: its hash (fields only, as
    in ROS 2's RIHS01) is what it was before, so ROS 2 peers still match."""
    battery = robot.BATTERY_STATUS.type_name
    assert TYPES.hash(battery) == \
        "RIHS01_c761dc027c3b333c5284bf32a4cbc239864cae975cdf375675eb53fbf4ea2d8b"
    assert [name for name, _type in TYPES.fields(battery)] == [
        "header", "charging_state", "charge_percent", "voltage", "charging", "dock_state"]


# ---------------------------------------------------------------------- perception
def test_the_tracker_and_the_robot_client_agree_on_objects_say_and_speeds(bus: Context) -> None:
    tracker = tracker_component.start(bus, NodeSpec("tracker", "tracker", "/robot3"))
    client = BusRobot(Node("bt", "/elsewhere", context=bus), "/robot3")
    graph = bus.graph
    try:
        assert client.objects() == []  # the first look subscribes
        settle(graph, lambda: len(endpoints(graph, "/elsewhere/bt",
                                            [EntityKind.SUBSCRIPTION])) >= 3
               and len(endpoints(graph, "/robot3/tracker", [EntityKind.SUBSCRIPTION])) >= 2)
        assert_serves(graph, "/robot3/tracker", "/robot3", [perception.OBJECTS])
        assert_subscribes(graph, "/robot3/tracker", "/robot3", [robot.POSE])
        assert_subscribes(graph, "/robot3/tracker", "/robot3/detector", [detector.PREDICTIONS])
        assert_subscribes(graph, "/elsewhere/bt", "/robot3", [perception.OBJECTS])
        published = {(entity.topic, entity.type_name) for entity in endpoints(
            graph, "/elsewhere/bt", [EntityKind.PUBLISHER])}
        assert published == {(topic.full_name("/robot3"), topic.type_name)
                             for topic in (perception.SAY, robot.CMD_VEL, HELP)}
    finally:
        tracker.stop()


def test_the_simulator_plans_on_the_objects_its_robots_tracker_publishes(
        bus: Context, shared: Path) -> None:
    tracker = tracker_component.start(bus, NodeSpec("tracker", "tracker", "/robot3"))
    node = Node("arnl", "/robot3", context=bus)
    ObjectFeed(node, SimulationLoop(Simulator(read_map(shared / "maps" / "AMROffice.map"),
                                              start="Dock")))
    graph = bus.graph
    try:
        settle(graph, lambda: len(endpoints(graph, "/robot3/arnl",
                                            [EntityKind.SUBSCRIPTION])) >= 1)
        assert_serves(graph, "/robot3/tracker", "/robot3", [perception.OBJECTS])
        assert_subscribes(graph, "/robot3/arnl", "/robot3", [perception.OBJECTS])
    finally:
        tracker.stop()
