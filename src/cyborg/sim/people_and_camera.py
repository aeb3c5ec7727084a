"""The simulator component's people and cameras: their parameters, and starting them.

The simulator (:mod:`cyborg.sim.component`) declares these bus parameters besides its own
(all read-only):

================  =======================================================================
parameter         meaning (default)
================  =======================================================================
``people``        how many people walk at random among the map's goals (:data:`PEOPLE`, 0),
                  besides the map's own ``Sim.Person`` objects (:mod:`cyborg.sim.people_sources`)
``people_seed``   the seed of their starts, waypoints, speeds and pauses (0)
``camera``        whether each robot has a simulated camera publishing detections under its
                  detector namespace (:data:`CAMERA`, false; :mod:`cyborg.sim.camera_node`)
``camera_image``  whether that camera also draws ``detection_image`` (false: it costs)
================  =======================================================================

:func:`make_crowd` builds the people (None when nobody walks); :func:`start_cameras` starts a
camera node (:data:`CAMERA_NAME`) for each robot, and :func:`publish_people` the people's true
poses under the first robot's namespace.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import NamedTuple

from cyborg.bus import Context, Node
from cyborg.bus.component import NodeSpec
from cyborg.interfaces.detector import detector_of_robot
from cyborg.nav.arnl_map import ArnlMap, MapError
from cyborg.nav.planner import Planner
from cyborg.sim.camera import SimCamera
from cyborg.sim.camera_node import SimCameraNode
from cyborg.sim.loop import RobotLoop
from cyborg.sim.people import Crowd
from cyborg.sim.people_node import PeoplePublisher
from cyborg.sim.people_sources import people_on_map, random_people
from cyborg.sim.sights import Sights, crowd_sights, placed_objects
from cyborg.sim.simulator import Simulator

log = logging.getLogger("cyborg.sim")

PEOPLE = 0
"""How many people walk at random unless told otherwise (the map's own walk anyway)."""
CAMERA = False
"""Whether the robots have simulated cameras unless told otherwise."""
CAMERA_NAME = "sim_camera"
"""The simulated camera's node name, under the robot's detector namespace."""


class Extras(NamedTuple):
    """The people and camera parameters' values (see the module doc)."""

    people: int
    seed: int
    camera: bool
    image: bool


def declare_extras(node: Node, spec: NodeSpec) -> Extras:
    """Declares the parameters on ``node``; refuses a negative ``people`` naming the entry."""
    given = spec.parameters.get("people", PEOPLE)
    if isinstance(given, bool) or not isinstance(given, int) or given < 0:
        raise spec.error(f"parameter `people` must be a whole number, 0 or more, not {given!r}")
    params = node.parameters
    people = params.declare("people", PEOPLE, "people walking at random", read_only=True)
    seed = params.declare("people_seed", 0, "seed of the people", read_only=True)
    camera = params.declare("camera", CAMERA, "simulated camera with detections",
                            read_only=True)
    image = params.declare("camera_image", False, "the camera draws detection_image",
                           read_only=True)
    return Extras(int(people), int(seed), bool(camera), bool(image))


def make_crowd(arnl_map: ArnlMap, planner: Planner, extras: Extras,
               starts: Sequence[tuple[float, float]]) -> Crowd | None:
    """The map's people and ``extras.people`` more at random, away from the robots' ``starts``.

    None when nobody walks. MapError for a bad ``Sim.Person``, ValueError for a map without
    room for people.
    """
    plans = people_on_map(arnl_map, planner, extras.seed)
    plans += random_people(arnl_map, planner, extras.people, extras.seed, keep_away=starts)
    return Crowd(planner, plans, seed=extras.seed) if plans else None


def start_cameras(context: Context, robots: Sequence[tuple[Node, RobotLoop]],
                  crowd: Crowd | None, extras: Extras) -> list[Node]:
    """A camera node for each robot (its bus node and loop) if ``extras.camera``; the nodes.

    MapError for a bad ``Sim.Object`` on the map (:mod:`cyborg.sim.sights`).
    """
    if not extras.camera:
        return []
    nodes: list[Node] = []
    first = robots[0][1].simulator.map
    placed = {id(first): (first, placed_objects(first))}  # a bad Sim.Object fails here

    def sights(sim: Simulator) -> Sights:
        known = placed.get(id(sim.map))
        if known is None or known[0] is not sim.map:  # a map loaded while running
            try:
                objects = placed_objects(sim.map)
            except MapError as exc:  # the simulation goes on; the camera sees no objects
                log.warning("%s: the camera sees no objects: %s", sim.map.source, exc)
                objects = Sights.none()
            known = placed[id(sim.map)] = (sim.map, objects)
        on_map = crowd is not None and crowd.routes.planner is sim.planner
        return crowd_sights(crowd if on_map else None).joined(known[1])

    try:
        for index, (robot_node, loop) in enumerate(robots):
            node = Node(CAMERA_NAME, detector_of_robot(robot_node.namespace), context=context)
            nodes.append(node)
            laser = loop.simulator.laser
            camera = SimCamera(laser.occupied, laser.origin, laser.resolution,
                               seed=extras.seed + index)
            SimCameraNode(node, loop, camera, sights, image=extras.image)
    except BaseException:
        for node in nodes:
            node.destroy()
        raise
    return nodes


def publish_people(node: Node, loop: RobotLoop, crowd: Crowd | None) -> None:
    """The people's true poses on ``node`` (``sim/people``), when people walk."""
    if crowd is not None:
        PeoplePublisher(node, loop, crowd)
