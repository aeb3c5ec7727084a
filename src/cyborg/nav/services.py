"""Navigation services on the bus, with the 2018 names and without the 2018 defects.

Under the robot's namespace (``/cyborg`` by default), as :mod:`cyborg.interfaces.robot` names
them (:data:`~cyborg.interfaces.robot.NAVIGATION_SERVICES`):

===============================  ==============================  ===============================
service                          type                            answers
===============================  ==============================  ===============================
``nav/get_available_goals``      cyborg_msgs/srv/AvailableGoals  every Goal, GoalWithHeading and
                                                                 Dock; headings in radians
``nav/get_distance_to_goal``     cyborg_msgs/srv/DistanceToGoal  planned path length from the
                                                                 robot; +inf when there is none
``nav/get_closest_goal``         cyborg_msgs/srv/ClosestGoal     nearest goal *by path length*
``make_plan``                    cyborg_msgs/srv/MakePlan        a path (static map, as ARNL)
``load_map_file``                cyborg_msgs/srv/LoadMapFile     switch maps at runtime
===============================  ==============================  ===============================

The map can be switched while running: :class:`NavigationMap` holds the current map and its
planner and tells listeners (the simulator) when it changes. A map that fails to load leaves the
old one in place and the reply says why (file and line). Loading runs on its own thread, one
map at a time, so the node's other services (the simulator's ``stop``) keep answering; only
``.map`` files are read, so the reply never quotes some other file to a caller.

Requests are checked before the handlers run: a pose with a NaN or infinite number is refused
with ``bad request: goal.x: nan is not a finite number`` (see :func:`require_finite`).
"""

from __future__ import annotations

import dataclasses
import logging
import math
import threading
from collections.abc import Callable
from pathlib import Path as FilePath
from typing import Any

import numpy as np

from cyborg.bus import Node, new_message
from cyborg.bus.services import RequestError, Responder
from cyborg.interfaces.robot import (
    AVAILABLE_GOALS,
    CLOSEST_GOAL,
    DISTANCE_TO_GOAL,
    LOAD_MAP_FILE,
    MAKE_PLAN,
    NAVIGATION_SERVICES,
)
from cyborg.nav.arnl_map import ArnlMap, MapError, read_map
from cyborg.nav.geometry import Pose, Pose2D
from cyborg.nav.planner import Planner, PlanResult

log = logging.getLogger("cyborg.nav")


def require_finite(message: Any, path: str = "") -> None:
    """RequestError naming the first number in ``message`` (a request, at any depth) that is
    NaN or infinite, e.g. ``goal.position.x``: no pose, distance or heading can be one."""
    if isinstance(message, float | np.floating):
        if not math.isfinite(message):
            raise RequestError(path, f"{message!r} is not a finite number")
    elif isinstance(message, np.ndarray) and message.dtype.kind == "f":
        bad = np.flatnonzero(~np.isfinite(message))
        if len(bad):
            raise RequestError(f"{path}[{bad[0]}]", f"{message.flat[bad[0]]!r} is not a finite "
                                                    "number")
    elif isinstance(message, list | tuple):
        for index, item in enumerate(message):
            require_finite(item, f"{path}[{index}]")
    elif dataclasses.is_dataclass(message) and not isinstance(message, type):
        for item in dataclasses.fields(message):
            value = getattr(message, item.name)
            if not isinstance(value, str | bool | int):
                require_finite(value, f"{path}.{item.name}" if path else item.name)


class NavigationMap:
    """The map in use and its planner; thread-safe; ``on_change`` listeners get new maps."""

    def __init__(self, arnl_map: ArnlMap, planner: Planner | None = None) -> None:
        self._lock = threading.Lock()
        self.map = arnl_map
        self.planner = planner or Planner(arnl_map)
        self.listeners: list[Callable[[ArnlMap, Planner], None]] = []

    def load(self, path: str | FilePath) -> ArnlMap:
        """Read and switch to another map; MapError leaves the current one in place.

        Listeners (the simulator) switch first: if one refuses the map, by raising, the
        services keep the map the simulator still drives on."""
        arnl_map = read_map(path)
        planner = Planner(arnl_map)
        for listener in list(self.listeners):
            listener(arnl_map, planner)
        with self._lock:
            self.map, self.planner = arnl_map, planner
        return arnl_map

    def plan(self, start: Pose2D, goal: Pose2D, use_heading: bool = False) -> PlanResult:
        with self._lock:
            planner = self.planner
        return planner.plan(start, goal, use_heading=use_heading)


class NavigationServices:
    """Registers the navigation services on ``node``; ``pose()`` gives the robot's pose."""

    def __init__(self, node: Node, maps: NavigationMap,
                 pose: Callable[[], Pose2D | None]) -> None:
        self.node, self.maps, self.pose = node, maps, pose
        types = node.types
        self._goal_type = types.message_class("cyborg_msgs/msg/GoalWithHeading")
        self._classes = {service: types.message_class(service.response_type)
                         for service in NAVIGATION_SERVICES}
        self._loading = threading.Lock()  # one map at a time
        for service, handler in ((AVAILABLE_GOALS, self.available_goals),
                                 (DISTANCE_TO_GOAL, self.distance_to_goal),
                                 (CLOSEST_GOAL, self.closest_goal),
                                 (MAKE_PLAN, self.make_plan)):
            service.server(node, handler).checks.append(require_finite)
        LOAD_MAP_FILE.server(node, self.load_map_file, deferred=True)

    def _robot(self) -> Pose2D:
        pose = self.pose()
        if pose is None:
            raise RuntimeError("the robot's pose is not known yet (nothing on the pose topic)")
        return pose

    # ------------------------------------------------------------------ handlers
    def available_goals(self, _request: Any) -> Any:
        goals = [self._goal_type(name=item.name, comment=item.description,
                                 position=Pose2D(item.x, item.y, item.theta).to_message(
                                     self.node.types), has_heading=item.has_heading)
                 for item in self.maps.map.goals()]
        return self._classes[AVAILABLE_GOALS](goals=goals)

    def distance_to_goal(self, request: Any) -> Any:
        goal = Pose.from_message(request.goal).to_pose2d()
        result = self.maps.plan(self._robot(), goal)
        return self._classes[DISTANCE_TO_GOAL](distance=result.length)

    def closest_goal(self, _request: Any) -> Any:
        robot = self._robot()
        best_name, best = "", math.inf
        for item in self.maps.map.goals():
            length = self.maps.plan(robot, Pose2D(item.x, item.y)).length
            if length < best:
                best_name, best = item.name, length
        return self._classes[CLOSEST_GOAL](name=best_name, distance=best)

    def make_plan(self, request: Any) -> Any:
        start = Pose2D.from_message(request.start) if request.use_start else self._robot()
        goal = Pose2D.from_message(request.goal)
        result = self.maps.plan(start, goal)
        response = self._classes[MAKE_PLAN]
        if result.path is None:
            empty = new_message(self.node.types, "nav_msgs/msg/Path",
                                {"header": {"frame_id": "map"}})
            return response(found=False, message=f"{result.code}: {result.reason}", path=empty,
                            length=math.inf)
        return response(found=True, message="", path=result.path.to_message(self.node.types),
                        length=result.length)

    def load_map_file(self, request: Any, responder: Responder) -> None:
        """Load on a thread of its own and answer from there (deferred), one map at a time."""
        reply = self._classes[LOAD_MAP_FILE]
        path = request.path
        if not path.lower().endswith(".map"):
            responder.reply(reply(success=False, message=f"load_map_file: {path[:80]!r} is not "
                                                          "an ARNL map (a .map file)"))
            return
        if not self._loading.acquire(blocking=False):
            responder.reply(reply(success=False, message="another map is loading; try again "
                                                          "when it is done"))
            return
        threading.Thread(target=self._load, args=(path, responder), daemon=True,
                         name="cyborg-load-map").start()

    def _load(self, path: str, responder: Responder) -> None:
        """Load, free the one-at-a-time lock, then answer: a caller that asks again as soon
        as it has its answer must find the lock free."""
        reply = self._classes[LOAD_MAP_FILE]
        try:
            arnl_map = self.maps.load(path)
        except MapError as exc:
            self._loading.release()
            log.warning("load_map_file: %s", exc)
            responder.reply(reply(success=False, message=str(exc)))
        except Exception as exc:  # a listener (the simulator) failed: say so, keep serving
            self._loading.release()
            log.error("load_map_file %r: %s: %s", path, type(exc).__name__, exc, exc_info=True)
            responder.fail(exc)
        else:
            self._loading.release()
            responder.reply(reply(success=True, message=f"loaded {arnl_map.source}: "
                                                        f"{len(arnl_map.goals())} goals"))
