"""The tree runner on the bus: load a behavior3editor tree, tick it, publish what it does.

Under the runner's namespace (``/cyborg/bt`` by default, as in 2018):

==========================  ==================================  ==================================
name                        type                                what
==========================  ==================================  ==================================
``behavior_tree``           cyborg_msgs/BehaviorTree            latched: the structure as JSON
                                                                (schema cyborg.bt.structure/1),
                                                                again after every reload
``behavior_tree_updates``   cyborg_msgs/BehaviorTreeNodes       latched: ids of the active path,
                                                                published when it changes
``enabled``                 std_msgs/Bool                       latched: whether the tree ticks
``status``                  cyborg_msgs/BehaviorTreeStatus      every tick: nodes visited with
                                                                their status and wall time
                                                                (timed while someone listens),
                                                                tick, duration
``enable``                  std_srvs/SetBool                    service: run or pause the tree
``reload``                  cyborg_msgs/ReloadTree              service: load the file again
==========================  ==================================  ==================================

plus the per-node controls of :mod:`cyborg.nodes.tree_control` (hooks, breakpoints, blackboard).

**Enable and disable.** Unlike 2018, disabling *halts* the tree: every RUNNING node is halted,
so a MoveTo cancels its goal and the robot stops. Enabling starts the tree afresh from its root
(memories of halted nodes are reset, as after any halt). The flag is latched on ``enabled``.

**Reload.** The file (or another one) is loaded and checked first; a file with errors is
rejected with every problem in the reply and the running tree keeps running. A good file
replaces the tree between two ticks: the old tree is halted, the global blackboard and the
hooks on nodes that still exist are kept, and the new structure is published.

**Time.** The tree ticks on the clock it is given: the wall clock, or simulated time from
``/clock`` (:class:`cyborg.bus.SimClock`) with ``use_sim_time``.
"""

from __future__ import annotations

import json
import logging
import threading
from pathlib import Path
from typing import Any

import numpy as np

from cyborg.bt import (
    Blackboard,
    Clock,
    NodeRegistry,
    Tree,
    TreeLoadError,
    TreeRunner,
    default_registry,
    load_tree,
)
from cyborg.bt.snapshot import TickSnapshot
from cyborg.bus import Node, Qos, SimClock
from cyborg.nodes.robot import ROBOT, Robot
from cyborg.nodes.tree_control import TreeControl

log = logging.getLogger("cyborg.nodes")


class TreeRunnerNode:
    """Runs one tree file on the bus; see the module docstring."""

    def __init__(self, node: Node, path: str | Path, *, tree: str | None = None,
                 rate_hz: float = 10.0, clock: Clock | None = None, robot: Robot | None = None,
                 registry: NodeRegistry | None = None, enabled: bool = True) -> None:
        """Load the tree (raises :class:`~cyborg.bt.TreeLoadError`) and set up the topics and
        services; :meth:`start` begins ticking."""
        self.node, self.path, self.tree_choice = node, Path(path), tree
        self.registry = registry if registry is not None else default_registry()
        self.clock = clock
        self.resources: dict[str, Any] = {ROBOT: robot} if robot is not None else {}
        self.tree = self._load(self.path, Blackboard(resources=self.resources))
        self.runner = TreeRunner(self.tree, rate_hz=rate_hz)
        self._enabled = enabled
        self._active: tuple[str, ...] | None = None
        self._lock = threading.Lock()
        types = node.types
        latched = Qos.latched()
        self._structure = node.create_publisher("behavior_tree", "cyborg_msgs/msg/BehaviorTree",
                                                latched)
        self._updates = node.create_publisher("behavior_tree_updates",
                                              "cyborg_msgs/msg/BehaviorTreeNodes", latched)
        self._enabled_pub = node.create_publisher("enabled", "std_msgs/msg/Bool", latched)
        self._status = node.create_publisher("status", "cyborg_msgs/msg/BehaviorTreeStatus")
        self._classes = {name: types.message_class(name) for name in (
            "cyborg_msgs/msg/BehaviorTree", "cyborg_msgs/msg/BehaviorTreeNodes",
            "std_msgs/msg/Bool", "cyborg_msgs/msg/BehaviorTreeStatus",
            "builtin_interfaces/msg/Time", "std_srvs/srv/SetBool_Response",
            "cyborg_msgs/srv/ReloadTree_Response")}
        node.create_service("enable", "std_srvs/srv/SetBool", self._on_enable)
        node.create_service("reload", "cyborg_msgs/srv/ReloadTree", self._on_reload)
        self.control = TreeControl(node, lambda: self.tree)
        self.runner.add_listener(self._on_tick)
        self._publish_structure()
        self._publish_enabled()
        self._thread: threading.Thread | None = None

    # ------------------------------------------------------------------ loading
    def _load(self, path: Path, blackboard: Blackboard) -> Tree:
        return load_tree(path, tree=self.tree_choice, registry=self.registry, clock=self.clock,
                         blackboard=blackboard)

    def reload(self, path: str | Path | None = None) -> Tree:
        """Load ``path`` (default: the current file) and tick it from the next tick on.

        Raises :class:`~cyborg.bt.TreeLoadError` (the old tree keeps running) on errors.
        """
        path = Path(path) if path else self.path
        old = self.tree
        tree = self._load(path, Blackboard(old.blackboard.globals,
                                           resources=old.blackboard.resources))
        with self._lock:
            self.runner.replace_tree(tree)
            self.tree, self.path, self._active = tree, path, None
        self.control.tree_replaced(old, tree)
        self._publish_structure()
        log.info("reloaded %s: %r, %d nodes", path, tree.title, len(tree))
        return tree

    # ------------------------------------------------------------------ running
    @property
    def enabled(self) -> bool:
        return self._enabled

    def start(self) -> None:
        """Tick in a background thread; on simulated time, from the first ``/clock`` on."""
        if self._thread is not None:
            raise RuntimeError("the tree runner is already started")
        if not self._enabled:
            self.runner.pause()
        self._thread = threading.Thread(target=self._run, name="cyborg-tree", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        clock = self.clock
        if isinstance(clock, SimClock) and not clock.started:
            log.info("waiting for /clock (use_sim_time)")
            while not clock.wait_for_time(1.0):
                if self.runner.stopped:
                    return
        self.runner.run()

    def set_enabled(self, enabled: bool) -> None:
        """Run (True) or halt and pause (False) the tree; see the module docstring."""
        with self._lock:
            if enabled == self._enabled:
                return
            self._enabled = enabled
            if enabled:
                self.runner.resume()
            else:
                self.runner.pause(halt=True)
                self._active = None
        self._publish_enabled()
        if not enabled:
            self._publish_active(())

    def stop(self) -> None:
        """Stop ticking and halt the tree (the robot stops); withdraws nothing from the bus."""
        self.runner.stop()
        if self._thread is not None:
            self._thread.join(5.0)

    def destroy(self) -> None:
        self.stop()
        self.control.destroy()
        self.node.destroy()

    # ------------------------------------------------------------------ publishing
    def _publish_structure(self) -> None:
        text = json.dumps(self.tree.structure.to_json(), separators=(",", ":"))
        self._structure.publish(self._classes["cyborg_msgs/msg/BehaviorTree"](tree=text))

    def _publish_enabled(self) -> None:
        self._enabled_pub.publish(self._classes["std_msgs/msg/Bool"](data=self._enabled))

    def _publish_active(self, active: tuple[str, ...]) -> None:
        self._updates.publish(self._classes["cyborg_msgs/msg/BehaviorTreeNodes"](
            ids=list(active)))

    def _on_tick(self, snapshot: TickSnapshot) -> None:
        active = tuple(snapshot.active)
        if active != self._active:
            self._active = active
            self._publish_active(active)
        hooks = self.tree.hooks
        if self._status.subscription_count() == 0:
            if hooks.timing:
                hooks.timing = False  # nodes run unwrapped again
            return  # nobody listens: skip building the message
        if not hooks.timing:
            hooks.timing = True  # per-node timings from the next tick on
        seconds = snapshot.time
        stamp = self._classes["builtin_interfaces/msg/Time"](
            sec=int(seconds), nanosec=int((seconds % 1.0) * 1e9) % 1_000_000_000)
        visited = snapshot.visited
        self._status.publish(self._classes["cyborg_msgs/msg/BehaviorTreeStatus"](
            stamp=stamp, tick=snapshot.tick, duration=snapshot.duration,
            status=int(snapshot.status), visited_ids=[uid for uid, _ in visited],
            visited_statuses=np.array([int(status) for _, status in visited], np.uint8),
            visited_durations=np.array(snapshot.visit_durations, np.float32),
            active_ids=list(active), halted_ids=snapshot.halted))

    # ------------------------------------------------------------------ services
    def _on_enable(self, request: Any) -> Any:
        self.set_enabled(bool(request.data))
        return self._classes["std_srvs/srv/SetBool_Response"](
            success=True, message="enabled" if self._enabled else "disabled")

    def _on_reload(self, request: Any) -> Any:
        response = self._classes["cyborg_msgs/srv/ReloadTree_Response"]
        try:
            tree = self.reload(request.path or None)
        except TreeLoadError as exc:
            problems = "\n".join(str(problem) for problem in exc.problems)
            return response(success=False, message=problems or str(exc))
        return response(success=True, message=f"loaded {tree.title!r} ({len(tree)} nodes) "
                                              f"from {self.path}")
