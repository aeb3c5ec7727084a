"""Navigation services on the bus, with the 2018 names and without the 2018 defects.

Under the robot's namespace (``/cyborg`` by default):

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
old one in place and the reply says why (file and line).
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from pathlib import Path as FilePath
from typing import Any

from cyborg.bus import Node, new_message
from cyborg.nav.arnl_map import ArnlMap, MapError, read_map
from cyborg.nav.geometry import Pose, Pose2D
from cyborg.nav.planner import Planner, PlanResult


class NavigationMap:
    """The map in use and its planner; thread-safe; ``on_change`` listeners get new maps."""

    def __init__(self, arnl_map: ArnlMap, planner: Planner | None = None) -> None:
        self._lock = threading.Lock()
        self.map = arnl_map
        self.planner = planner or Planner(arnl_map)
        self.listeners: list[Callable[[ArnlMap, Planner], None]] = []

    def load(self, path: str | FilePath) -> ArnlMap:
        """Read and switch to another map; MapError leaves the current one in place."""
        arnl_map = read_map(path)
        planner = Planner(arnl_map)
        with self._lock:
            self.map, self.planner = arnl_map, planner
        for listener in list(self.listeners):
            listener(arnl_map, planner)
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
        self._classes = {name: types.message_class(f"cyborg_msgs/srv/{name}_Response")
                         for name in ("AvailableGoals", "DistanceToGoal", "ClosestGoal",
                                      "MakePlan", "LoadMapFile")}
        node.create_service("nav/get_available_goals", "cyborg_msgs/srv/AvailableGoals",
                            self.available_goals)
        node.create_service("nav/get_distance_to_goal", "cyborg_msgs/srv/DistanceToGoal",
                            self.distance_to_goal)
        node.create_service("nav/get_closest_goal", "cyborg_msgs/srv/ClosestGoal",
                            self.closest_goal)
        node.create_service("make_plan", "cyborg_msgs/srv/MakePlan", self.make_plan)
        node.create_service("load_map_file", "cyborg_msgs/srv/LoadMapFile", self.load_map_file)

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
        return self._classes["AvailableGoals"](goals=goals)

    def distance_to_goal(self, request: Any) -> Any:
        goal = Pose.from_message(request.goal).to_pose2d()
        result = self.maps.plan(self._robot(), goal)
        return self._classes["DistanceToGoal"](distance=result.length)

    def closest_goal(self, _request: Any) -> Any:
        robot = self._robot()
        best_name, best = "", math.inf
        for item in self.maps.map.goals():
            length = self.maps.plan(robot, Pose2D(item.x, item.y)).length
            if length < best:
                best_name, best = item.name, length
        return self._classes["ClosestGoal"](name=best_name, distance=best)

    def make_plan(self, request: Any) -> Any:
        start = Pose2D.from_message(request.start) if request.use_start else self._robot()
        goal = Pose2D.from_message(request.goal)
        result = self.maps.plan(start, goal)
        response = self._classes["MakePlan"]
        if result.path is None:
            empty = new_message(self.node.types, "nav_msgs/msg/Path",
                                {"header": {"frame_id": "map"}})
            return response(found=False, message=f"{result.code}: {result.reason}", path=empty,
                            length=math.inf)
        return response(found=True, message="", path=result.path.to_message(self.node.types),
                        length=result.length)

    def load_map_file(self, request: Any) -> Any:
        try:
            arnl_map = self.maps.load(request.path)
        except MapError as exc:
            return self._classes["LoadMapFile"](success=False, message=str(exc))
        return self._classes["LoadMapFile"](
            success=True, message=f"loaded {arnl_map.source}: {len(arnl_map.goals())} goals")
