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
planner and tells listeners when it changes (the simulator before the switch, the map's
publisher, :class:`~cyborg.nav.map_message.MapPublisher`, after it). A map that fails to load
leaves the old one in place and the reply says why (file and line). Loading runs on its own
thread, one map at a time, so the node's other services (the simulator's ``stop``) keep
answering; only ``.map`` files are read, so the reply never quotes some other file to a caller.

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

from cyborg.bus import Node
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import GoalWithHeading
from cyborg.bus.msgs.cyborg_msgs.srv import (
    AvailableGoals,
    AvailableGoals_Request,
    AvailableGoals_Response,
    ClosestGoal,
    ClosestGoal_Request,
    ClosestGoal_Response,
    DistanceToGoal,
    DistanceToGoal_Request,
    DistanceToGoal_Response,
    LoadMapFile,
    LoadMapFile_Request,
    LoadMapFile_Response,
    MakePlan,
    MakePlan_Request,
    MakePlan_Response,
)
from cyborg.bus.msgs.nav_msgs.msg import Path as PathMessage
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.bus.services import RequestError, Responder
from cyborg.interfaces.robot import (
    AVAILABLE_GOALS,
    CLOSEST_GOAL,
    DISTANCE_TO_GOAL,
    LOAD_MAP_FILE,
    MAKE_PLAN,
)
from cyborg.nav.arnl_map import ArnlMap, MapError, read_map
from cyborg.nav.geometry import Pose, Pose2D
from cyborg.nav.planner import Planner, PlanResult

log = logging.getLogger("cyborg.nav")


def require_finite(message: Any, path: str = "") -> None:
    """Refuses a request holding a NaN or an infinite number, at any depth.

    Raises :class:`~cyborg.bus.services.RequestError` naming the first such number in
    ``message`` (``goal.position.x``): no pose, distance or heading can be one. A service
    server runs it, as one of its checks, before the handler.
    """
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
    """The map in use and its planner; thread-safe.

    Two lists of listeners follow a switch of maps (:meth:`load`): ``listeners`` take the new
    map and its planner before the switch and may refuse it (the simulator, which must drive
    on it), ``switched`` are told of it once it is in use (the map's publisher).
    """

    def __init__(self, arnl_map: ArnlMap, planner: Planner | None = None) -> None:
        self._lock = threading.Lock()
        self.map = arnl_map
        self.planner = planner or Planner(arnl_map)
        self.listeners: list[Callable[[ArnlMap, Planner], None]] = []
        """Run before the switch, on the loading thread; one that raises refuses the map."""
        self.switched: list[Callable[[ArnlMap], None]] = []
        """Run after a switch, on the loading thread, with the map now in use."""

    def load(self, path: str | FilePath) -> ArnlMap:
        """Read and switch to another map; MapError leaves the current one in place.

        Listeners (the simulator) switch first: if one refuses the map, by raising, the
        services keep the map the simulator still drives on. Then the map is in use and the
        ``switched`` listeners run; one that fails is logged and the others still run, since
        the switch itself has happened.
        """
        arnl_map = read_map(path)
        planner = Planner(arnl_map)
        for listener in list(self.listeners):
            listener(arnl_map, planner)
        with self._lock:
            self.map, self.planner = arnl_map, planner
        for switched in list(self.switched):
            try:
                switched(arnl_map)
            except Exception as exc:  # the map is in use all the same
                log.error("after switching to %s: %s: %s", arnl_map.source,
                          type(exc).__name__, exc, exc_info=True)
        return arnl_map

    def plan(self, start: Pose2D, goal: Pose2D, use_heading: bool = False) -> PlanResult:
        """A path from ``start`` to ``goal`` on the map in use; safe from any thread.

        Without a path the result says why. ``use_heading``: the path's final heading is
        ``goal``'s.
        """
        with self._lock:
            planner = self.planner
        return planner.plan(start, goal, use_heading=use_heading)


class NavigationServices:
    """Registers the navigation services on ``node``; ``pose()`` gives the robot's pose."""

    def __init__(self, node: Node, maps: NavigationMap,
                 pose: Callable[[], Pose2D | None]) -> None:
        self.node, self.maps, self.pose = node, maps, pose
        self._loading = threading.Lock()  # one map at a time
        AVAILABLE_GOALS.server(node, self.available_goals).checks.append(require_finite)
        DISTANCE_TO_GOAL.server(node, self.distance_to_goal).checks.append(require_finite)
        CLOSEST_GOAL.server(node, self.closest_goal).checks.append(require_finite)
        MAKE_PLAN.server(node, self.make_plan).checks.append(require_finite)
        LOAD_MAP_FILE.server(node, self.load_map_file, deferred=True)

    def _robot(self) -> Pose2D:
        pose = self.pose()
        if pose is None:
            raise RuntimeError("the robot's pose is not known yet (nothing on the pose topic)")
        return pose

    # ------------------------------------------------------------------ handlers
    def available_goals(self, _request: AvailableGoals_Request) -> AvailableGoals_Response:
        """Every goal, goal with heading and dock of the map in use (headings in radians)."""
        goals = [GoalWithHeading(name=item.name, comment=item.description,
                                 position=Pose2D(item.x, item.y, item.theta).to_message(),
                                 has_heading=item.has_heading)
                 for item in self.maps.map.goals()]
        return AvailableGoals.Response(goals=goals)

    def distance_to_goal(self, request: DistanceToGoal_Request) -> DistanceToGoal_Response:
        """The planned path's length in metres from the robot to the goal; +inf without one.

        Raises RuntimeError while the robot's pose is not known.
        """
        goal = Pose.from_message(request.goal).to_pose2d()
        result = self.maps.plan(self._robot(), goal)
        return DistanceToGoal.Response(distance=result.length)

    def closest_goal(self, _request: ClosestGoal_Request) -> ClosestGoal_Response:
        """The goal nearest to the robot by planned path length (metres), not straight line.

        No reachable goal gives an empty name and +inf; raises RuntimeError while the robot's
        pose is not known.
        """
        robot = self._robot()
        best_name, best = "", math.inf
        for item in self.maps.map.goals():
            length = self.maps.plan(robot, Pose2D(item.x, item.y)).length
            if length < best:
                best_name, best = item.name, length
        return ClosestGoal.Response(name=best_name, distance=best)

    def make_plan(self, request: MakePlan_Request) -> MakePlan_Response:
        """A path on the static map from ``start`` (or the robot) to ``goal``, as ARNL plans.

        Without a path the reply says why and holds an empty path of +inf length.
        """
        start = Pose2D.from_message(request.start) if request.use_start else self._robot()
        goal = Pose2D.from_message(request.goal)
        result = self.maps.plan(start, goal)
        if result.path is None:
            empty = PathMessage(header=Header(stamp=Time(sec=0, nanosec=0), frame_id="map"),
                                poses=[])
            return MakePlan.Response(found=False, message=f"{result.code}: {result.reason}",
                                     path=empty, length=math.inf)
        return MakePlan.Response(found=True, message="", path=result.path.to_message(),
                                 length=result.length)

    def load_map_file(self, request: LoadMapFile_Request,
                      responder: Responder[LoadMapFile_Response]) -> None:
        """Load on a thread of its own and answer from there (deferred), one map at a time."""
        reply = LoadMapFile.Response
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

    def _load(self, path: str, responder: Responder[LoadMapFile_Response]) -> None:
        """Load, free the one-at-a-time lock, then answer (the loading thread).

        In that order: a caller that asks again as soon as it has its answer must find the
        lock free.
        """
        reply = LoadMapFile.Response
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
