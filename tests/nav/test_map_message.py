"""The map as displays get it (``map_geometry``): counts, categories, outlines, the hash, and the
publisher that follows a switch of maps."""

from __future__ import annotations

import logging
import math
from collections import Counter
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from cyborg.bus import BusConfig, Context, MessageTypes, Node
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import MapGeometry
from cyborg.bus.msgs.cyborg_msgs.msg import MapObject as ObjectMessage
from cyborg.interfaces import robot
from cyborg.nav.arnl_map import ArnlMap, parse_map, read_map
from cyborg.nav.map_message import MapPublisher, map_geometry
from cyborg.nav.planner import Planner
from cyborg.nav.services import NavigationMap
from tests.small_maps import room_map, write

EVERY_KIND = [
    'Goal 1000 1000 45.000000 "" ICON "plain"',
    'GoalWithHeading 2000 1000 90.000000 "faces north" ICON "north"',
    'Dock 1000 5000 -90.000000 "" ICON "Charger"',
    'RobotHome 3000 3000 30.000000 "" ICON "Home"',
    'RobotHome 0 0 0.000000 "" ICON "" 6000 1000 9000 2000',
    'ForbiddenLine 7000 4000 0.000000 "" ICON "" 7000 4000 9000 5000',
    'ForbiddenArea 500 250 30.000000 "" ICON "tilted" 6000 3000 8000 4000',
    'Sim.BoxObstacle 0 0 0.000000 "" ICON "box" 2000 2000 2500 2500',
    'Reflector 0 0 0.000000 "" ICON "" 100 200 300 400',
]
"""Every kind of object once; the forbidden area is rotated and its pose is not the origin."""


def every_kind_map() -> ArnlMap:
    text = room_map(EVERY_KIND, points=[(100, 100), (200, 100), (9900, 5900)])
    declared = 'MapInfo: BoundaryType Name=Reflector "Label=Reflector"\n'
    return parse_map(text.replace("2D-Map\n", "2D-Map\n" + declared, 1), "/maps/every kind.map")


def by_name(message: MapGeometry) -> dict[str, ObjectMessage]:
    return {item.name: item for item in message.objects if item.name}


# ---------------------------------------------------------------------- the message
def test_columbia_is_published_whole(shared: Path) -> None:
    arnl_map = read_map(shared / "maps" / "columbia.map")
    message = map_geometry(arnl_map)
    assert message.source == "columbia.map" and message.header.frame_id == robot.MAP_FRAME
    assert message.resolution == pytest.approx(0.020)  # "Resolution: 20" (mm)
    assert message.lines.dtype == message.points.dtype == np.float32
    assert len(message.points) == 2 * len(arnl_map.points) == 2 * 63_311
    assert len(message.lines) == 4 * len(arnl_map.lines) == 4 * 470
    assert len(message.objects) == len(arnl_map.objects) == 25
    np.testing.assert_array_equal(message.points.reshape(-1, 2),
                                  arnl_map.points.astype(np.float32))
    np.testing.assert_array_equal(message.lines.reshape(-1, 4), arnl_map.lines.astype(np.float32))
    assert Counter(item.category for item in message.objects) == {
        ObjectMessage.FORBIDDEN_LINE: 12, ObjectMessage.GOAL: 8, ObjectMessage.FORBIDDEN_AREA: 2,
        ObjectMessage.GOAL_WITH_HEADING: 2, ObjectMessage.HOME: 1}
    for item, sent in zip(arnl_map.objects, message.objects, strict=True):
        assert (sent.kind, sent.name, sent.description) == (item.kind, item.name,
                                                            item.description)
        corners = item.corners()
        expected = np.zeros(0) if corners is None else corners.reshape(-1)
        np.testing.assert_allclose(sent.outline, expected, atol=1e-5)
        assert sent.outline.dtype == np.float32
    assert "Goal 1" in by_name(message)  # names with spaces survive


def test_every_kind_of_object(shared: Path) -> None:
    arnl_map = every_kind_map()
    message = map_geometry(arnl_map, Time(sec=7, nanosec=5))
    assert message.source == "every kind.map" and message.header.stamp.sec == 7
    named = by_name(message)
    plain, north, dock, home = named["plain"], named["north"], named["Charger"], named["Home"]
    assert (plain.category, north.category, dock.category, home.category) == (
        ObjectMessage.GOAL, ObjectMessage.GOAL_WITH_HEADING, ObjectMessage.DOCK,
        ObjectMessage.HOME)
    assert (north.pose.x, north.pose.y, north.pose.theta) == pytest.approx((2.0, 1.0, math.pi / 2))
    assert north.description == "faces north"
    assert dock.pose.theta == pytest.approx(-math.pi / 2)
    assert plain.pose.theta == pytest.approx(math.pi / 4)  # as written; GOAL says to ignore it
    assert all(len(item.outline) == 0 for item in (plain, north, dock, home))

    regions = [item for item in message.objects if not item.name or item.name in ("tilted",
                                                                                    "box")]
    area, home_area, line, box, boundary = (
        next(item for item in regions if item.kind == kind)
        for kind in ("ForbiddenArea", "RobotHome", "ForbiddenLine", "Sim.BoxObstacle",
                     "Reflector"))
    # the area turns 30° about the map's origin, not about its pose (500, 250)
    tilted = arnl_map.objects[EVERY_KIND.index(next(
        cairn for cairn in EVERY_KIND if cairn.startswith("ForbiddenArea")))]
    corners = tilted.corners()
    assert corners is not None
    np.testing.assert_allclose(area.outline, corners.reshape(-1), atol=1e-6)
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    np.testing.assert_allclose(area.outline[:2], [6 * c - 3 * s, 6 * s + 3 * c], atol=1e-6)
    assert area.category == ObjectMessage.FORBIDDEN_AREA
    assert (line.category, list(line.outline)) == (ObjectMessage.FORBIDDEN_LINE,
                                                   [7.0, 4.0, 9.0, 5.0])
    assert home_area.category == ObjectMessage.HOME
    np.testing.assert_allclose(home_area.outline, [6, 1, 9, 1, 9, 2, 6, 2], atol=1e-6)
    assert box.category == ObjectMessage.SIM_OBSTACLE and len(box.outline) == 8
    # a declared boundary is a line (its two endpoints), not the rectangle around it
    assert boundary.category == ObjectMessage.OTHER
    np.testing.assert_allclose(boundary.outline, [0.1, 0.2, 0.3, 0.4], atol=1e-6)
    assert len(message.points) == 6 and len(message.lines) == 4 * 6


def test_the_message_crosses_the_wire_unchanged() -> None:
    types = MessageTypes()
    message = map_geometry(every_kind_map())
    data = bytes(types.serialize(message, robot.MAP_GEOMETRY.type_name))
    back = types.deserialize(data, robot.MAP_GEOMETRY.type_name)
    assert back.hash == message.hash and back.source == message.source
    np.testing.assert_array_equal(back.points, message.points)
    assert [(item.kind, item.category, list(item.outline)) for item in back.objects] == [
        (item.kind, item.category, list(item.outline)) for item in message.objects]


def test_a_map_without_resolution_or_anything_else() -> None:
    message = map_geometry(parse_map("2D-Map\n", "empty.map"))
    assert (message.source, message.resolution) == ("empty.map", 0.0)
    assert len(message.lines) == len(message.points) == len(message.objects) == 0
    assert message.lines.dtype == np.float32
    assert message.hash.startswith("sha256:") and len(message.hash) == len("sha256:") + 64
    assert map_geometry(parse_map("2D-Map\nResolution: 0\n", "zero.map")).resolution == 0.0


# ---------------------------------------------------------------------- the hash
TINY = "2D-Map\nResolution: 20\nCairn: Goal 1000 -2000 0 \"\" ICON \"a\"\nLINES\n0 0 1000 0\n" \
       "DATA\n20 40\n"


def test_the_hash_is_the_same_in_every_run() -> None:
    """Pinned: a hash that changed from one run, machine or Python to another would make every
    display fetch the map again (the value was worked out apart, from the layout that
    geometry_hash describes)."""
    first = map_geometry(parse_map(TINY, "/a/tiny.map"), Time(sec=1, nanosec=0))
    again = map_geometry(parse_map(TINY, "/b/other name.map"), Time(sec=2, nanosec=0))
    assert first.hash == again.hash == (
        "sha256:41604f0666fab464e5b7951499fc0732335220f0d894a87b022e28d5ed7027f4")


@pytest.mark.parametrize("changed", [
    TINY.replace("20 40\n", "20 60\n"),                    # one point
    TINY.replace("20 40\n", "20 40\n20 40\n"),             # one more point
    TINY.replace("0 0 1000 0", "0 0 1000 20"),             # one wall
    TINY.replace("\"a\"", "\"b\""),                        # a name
    TINY.replace("Goal 1000", "Goal 1020"),                # an object's pose
    TINY.replace("Cairn: Goal", "Cairn: GoalWithHeading"),  # its kind
    TINY.replace("Resolution: 20", "Resolution: 40"),      # the grid
    TINY.replace("DATA\n20 40\n", "DATA\n20 40\nLINES\n"),  # the wall moved away, no lines left
])
def test_the_hash_changes_with_the_geometry(changed: str) -> None:
    assert map_geometry(parse_map(changed, "x.map")).hash != \
        map_geometry(parse_map(TINY, "x.map")).hash


def test_points_and_lines_cannot_trade_places() -> None:
    """Lengths go into the hash: the same numbers split otherwise are another map."""
    as_points = "2D-Map\nDATA\n1 2\n3 4\n"
    as_line = "2D-Map\nLINES\n1 2 3 4\n"
    assert map_geometry(parse_map(as_points, "x.map")).hash != \
        map_geometry(parse_map(as_line, "x.map")).hash


# ---------------------------------------------------------------------- after a switch
@pytest.fixture
def node() -> Iterator[Node]:
    with Context(BusConfig.isolated()) as context:
        yield Node("arnl", "/cyborg", context=context)


def test_the_publisher_follows_the_navigation_map(node: Node, shared: Path) -> None:
    maps = NavigationMap(read_map(shared / "maps" / "triangle.map"))
    publisher = MapPublisher(node, maps, lambda: Time(sec=3, nanosec=0))
    assert publisher.last is not None and publisher.last.source == "triangle.map"
    first = publisher.last.hash
    maps.load(shared / "maps" / "office.map")
    assert publisher.last.source == "office.map" and publisher.last.hash != first
    assert publisher.last.header.stamp.sec == 3


def test_switched_listeners_run_after_the_switch_and_only_then(
        tmp_path: Path, shared: Path, caplog: pytest.LogCaptureFixture) -> None:
    maps = NavigationMap(read_map(shared / "maps" / "triangle.map"))
    seen: list[tuple[str, str]] = []

    def broken(_map: ArnlMap) -> None:
        raise RuntimeError("display gone")

    maps.switched += [broken, lambda new: seen.append((new.source, maps.map.source))]
    office = str(shared / "maps" / "office.map")
    with caplog.at_level(logging.ERROR, "cyborg.nav"):
        assert maps.load(office).source == office
    assert seen == [(office, office)]  # the map was in use when they ran; one failing is logged
    assert "display gone" in caplog.text

    def refuse(_map: ArnlMap, _planner: Planner) -> None:
        raise ValueError("the simulator cannot drive there")

    maps.listeners.append(refuse)
    with pytest.raises(ValueError):
        maps.load(write(tmp_path, "room.map", room_map([])))
    assert seen == [(office, office)] and maps.map.source == office
