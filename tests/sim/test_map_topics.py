"""What a display needs from the simulator, latched: the map (``map_geometry``, again after a
switch), the body (``footprint``) and where the laser sits (``/tf_static``), for a subscriber
that comes late, in another session."""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from cyborg.bus import Context, Node
from cyborg.bus.msgs.cyborg_msgs.msg import MapGeometry
from cyborg.bus.msgs.cyborg_msgs.srv import LoadMapFile
from cyborg.bus.wire import EntityKind
from cyborg.interfaces import robot
from cyborg.interfaces.contract import Topic
from cyborg.nav.arnl_map import read_map
from cyborg.nav.footprint import PIONEER_LX
from cyborg.nav.map_message import map_geometry
from cyborg.sim.laser import LaserSpec
from cyborg.sim.loop import SimulationLoop
from cyborg.sim.node import SimulatorNode
from cyborg.sim.simulator import Simulator
from tests.bus.bus_peer import linked_contexts, wait_for

NAMESPACE = "/robot7"


@pytest.fixture
def running(shared: Path) -> Iterator[tuple[Context, Simulator]]:
    """A simulator under :data:`NAMESPACE` in one session; the other session is returned."""
    with linked_contexts() as (here, there):
        sim = Simulator(read_map(shared / "maps" / "AMROffice.map"), start="Dock")
        loop = SimulationLoop(sim, speed=20)
        SimulatorNode(Node("arnl", NAMESPACE, context=here), loop)
        loop.start()
        try:
            assert wait_for(lambda: sim.time > 0.5, 10)  # it has been running a while
            yield there, sim
        finally:
            loop.stop()


class Latest:
    """Every message of one topic, and an event per arrival."""

    def __init__(self, node: Node, topic: Topic[Any]) -> None:
        self.messages: list[Any] = []
        self._arrived = threading.Condition()
        topic.subscription(node, self._take, namespace=NAMESPACE)

    def _take(self, message: Any) -> None:
        with self._arrived:
            self.messages.append(message)
            self._arrived.notify_all()

    def wait(self, accept: Callable[[Any], bool] = lambda _m: True, timeout: float = 20) -> Any:
        """The first message ``accept`` takes, waiting for it; fails after ``timeout`` s."""
        with self._arrived:
            found = self._arrived.wait_for(
                lambda: any(accept(message) for message in self.messages), timeout)
            assert found, f"nothing accepted among {len(self.messages)} messages"
            return next(message for message in self.messages if accept(message))


def test_a_late_subscriber_gets_map_footprint_and_laser_mount(
        running: tuple[Context, Simulator]) -> None:
    there, sim = running
    node = Node("display", "/", context=there)
    geometry, footprint, transforms, scan = (
        Latest(node, topic) for topic in (robot.MAP_GEOMETRY, robot.FOOTPRINT, robot.TF_STATIC,
                                          robot.SCAN))
    received: MapGeometry = geometry.wait()
    assert received.source == "AMROffice.map" and received.header.frame_id == "map"
    assert len(received.points) == 2 * len(sim.map.points) == 2 * 23_181
    assert len(received.lines) == 4 * len(sim.map.lines)
    assert len(received.objects) == len(sim.map.objects)
    assert received.hash == map_geometry(sim.map).hash

    body = footprint.wait()
    assert body.header.frame_id == robot.BASE_FRAME
    outline = [(point.x, point.y) for point in body.polygon.points]
    np.testing.assert_allclose(outline, PIONEER_LX.polygon(), atol=1e-6)

    mount = transforms.wait().transforms
    laser_frame = scan.wait().header.frame_id
    assert [(item.header.frame_id, item.child_frame_id) for item in mount] == [
        (robot.BASE_FRAME, laser_frame)]
    translation, rotation = mount[0].transform.translation, mount[0].transform.rotation
    assert (translation.x, translation.y, translation.z) == (LaserSpec().mount_x, 0.0, 0.0)
    assert (rotation.x, rotation.y, rotation.z, rotation.w) == (0.0, 0.0, 0.0, 1.0)

    graph = there.graph
    for name in ("/robot7/map_geometry", "/robot7/footprint", "/tf_static"):
        publishers = [entity for entity in graph.entities([EntityKind.PUBLISHER])
                      if entity.topic == name]
        assert [entity.latched for entity in publishers] == [True], name


def test_after_load_map_file_the_new_map_arrives(running: tuple[Context, Simulator],
                                                shared: Path) -> None:
    there, sim = running
    node = Node("display", "/", context=there)
    geometry = Latest(node, robot.MAP_GEOMETRY)
    before: MapGeometry = geometry.wait()
    assert before.source == "AMROffice.map"
    load = robot.LOAD_MAP_FILE.client(node, NAMESPACE)
    reply = load.call(LoadMapFile.Request(path=str(shared / "maps" / "columbia.map")), timeout=30)
    assert reply.success, reply.message
    after: MapGeometry = geometry.wait(lambda message: message.source == "columbia.map")
    assert after.hash != before.hash and after.hash == map_geometry(sim.map).hash
    assert len(after.points) == 2 * 63_311
    assert after.header.stamp.sec + after.header.stamp.nanosec * 1e-9 >= 0.5  # simulated time

    late = Latest(Node("late", "/", context=there), robot.MAP_GEOMETRY)
    assert late.wait().source == "columbia.map"  # latched: the map in use, not the first one
    assert [message.source for message in late.messages] == ["columbia.map"]

    refused = load.call(LoadMapFile.Request(path=str(shared / "maps" / "README.md")))
    assert not refused.success
    assert [message.source for message in geometry.messages] == ["AMROffice.map", "columbia.map"]
