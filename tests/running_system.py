"""Start the robot's system in-process for tests: simulator + tree runner on an isolated bus."""

from __future__ import annotations

import json
import signal
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from cyborg.app.launch import Launch, LaunchDescription
from cyborg.bus import BusConfig, Context, Node, new_message
from cyborg.bus.actions import ActionServer, GoalStatus
from cyborg.bus.component import NodeSpec
from cyborg.runner.component import RunningTree
from cyborg.runner.tree_runner import TreeRunnerNode
from cyborg.sim.component import RunningSimulator
from cyborg.sim.component import start as start_simulator
from cyborg.sim.simulator import Simulator


@dataclass
class System:
    context: Context
    launch: Launch
    client: Node

    @property
    def sim(self) -> Simulator:
        return self._simulator().loop.simulator

    def _simulator(self) -> RunningSimulator:
        return next(item for item in self.launch.running if isinstance(item, RunningSimulator))

    @property
    def runner(self) -> TreeRunnerNode:
        return next(item for item in self.launch.running
                    if isinstance(item, RunningTree)).runner

    def call(self, name: str, service: str, **fields: Any) -> Any:
        client = self.client.create_client(name, service)
        return client.call(new_message(self.client.types, f"{service}_Request", fields),
                           timeout=10)

    def stop_simulator(self) -> None:
        """Stops the simulator (the robot leaves the bus); :meth:`start_simulator` brings one
        back."""
        old = self._simulator()
        old.stop()
        self.launch.running.remove(old)

    def start_simulator(self, **parameters: Any) -> RunningSimulator:
        """Starts a new simulator with the launch's parameters (and ``parameters``)."""
        spec = next(spec for spec in self.launch.description.nodes if spec.kind == "simulator")
        new = start_simulator(self.context, replace(spec, parameters={**spec.parameters,
                                                                      **parameters}))
        assert isinstance(new, RunningSimulator), "one robot, not a fleet"
        self.launch.running.append(new)
        return new

    def goals(self) -> list[tuple[str, GoalStatus]]:
        """Every goal the simulator's navigator was given, in order: its name and status."""
        simulator = self._simulator()
        with simulator.loop.lock:
            server = next(entity for entity in simulator.node._entities
                          if isinstance(entity, ActionServer))
            return [(str(goal.request.goal_name), goal.status)
                    for goal in server._goals.values()]

    def uid(self, label: str) -> str:
        """The id of the one node with this label."""
        found = [node.uid for node in self.runner.tree if node.label == label]
        assert len(found) == 1, (label, found)
        return found[0]


def wait_until(predicate: Callable[[], object], timeout: float = 30.0,
               what: str = "condition") -> None:
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout:g} s waiting for {what}")
        time.sleep(0.01)


def wait_in_simulated_time(predicate: Callable[[], object], clock: Callable[[], float],
                           within: float, what: str = "condition",
                           wall_limit: float = 900.0) -> None:
    """Waits until ``predicate`` holds, failing once the simulated ``clock`` passes ``within``
    seconds without it: a busy machine slows the simulation, not the test's verdict.
    ``wall_limit`` (wall seconds) only ends a simulation that has stopped advancing."""
    deadline = time.monotonic() + wall_limit
    while not predicate():
        if clock() > within:
            raise AssertionError(f"{what} did not happen within {within:g} simulated s")
        if time.monotonic() > deadline:
            raise AssertionError(f"the simulation reached {clock():g} of {within:g} simulated s "
                                 f"in {wall_limit:g} wall s, waiting for {what}")
        time.sleep(0.01)


@contextmanager
def running_system(map_path: Path, tree_path: Path, *, speed: float = 20.0,
                   battery: float = 100.0, start: str = "", rate: float = 10.0,
                   registry_modules: list[str] | None = None,
                   simulator: bool = True,
                   sim_parameters: dict[str, Any] | None = None,
                   tracker: bool = False) -> Iterator[System]:
    """The simulator (unless not ``simulator``: then the tree runs on wall-clock time, its robot
    missing) and a tree runner under ``/cyborg``, on an isolated bus.

    ``sim_parameters`` adds to the simulator's (``people``, ``camera`` ...); with ``tracker``
    the tracker runs beside them on simulated time, as ``cyborg up`` starts it with the
    simulated camera.
    """
    with Context(BusConfig.isolated()) as context:
        sim: dict[str, Any] = {"map": str(map_path), "speed": speed, "battery": battery,
                               **(sim_parameters or {})}
        if start:
            sim["start"] = start
        tree: dict[str, Any] = {"tree_file": str(tree_path), "use_sim_time": simulator,
                                "robot_namespace": "/cyborg", "rate": rate}
        if registry_modules:
            tree["nodes"] = registry_modules
        launch = Launch(LaunchDescription([
            *([NodeSpec("simulator", "arnl", "/cyborg", sim)] if simulator else []),
            NodeSpec("tree_runner", "tree_runner", "/cyborg/bt", tree),
            *([NodeSpec("tracker", "tracker", "/cyborg", {"use_sim_time": True})]
              if tracker else [])]), context)
        launch.start()
        try:
            yield System(context, launch, Node("tester", "/test", context=context))
        finally:
            launch.stop()


def write_tree(folder: Path, root: dict[str, Any], name: str = "tree.b3.json") -> Path:
    """A one-tree behavior3editor project from nested ``{"name", "props", "children"}``."""
    nodes: dict[str, Any] = {}

    def add(spec: dict[str, Any]) -> str:
        uid = f"n{len(nodes) + 1}"
        entry: dict[str, Any] = {"id": uid, "name": spec["name"],
                                 "title": spec.get("title", spec["name"]), "description": "",
                                 "properties": spec.get("props", {}), "display": {"x": 0, "y": 0}}
        nodes[uid] = entry
        children = [add(child) for child in spec.get("children", [])]
        if spec.get("decorator"):
            entry["child"] = children[0]
        elif children or spec.get("composite"):
            entry["children"] = children
        return uid

    root_id = add(root)
    tree = {"version": "0.3.0", "scope": "tree", "id": "main", "title": "Test tree",
            "description": "", "root": root_id, "properties": {}, "nodes": nodes}
    project = {"version": "0.3.0", "scope": "project", "selectedTree": "main",
               "trees": [tree], "custom_nodes": []}
    path = folder / name
    path.write_text(json.dumps(project, indent=2))
    return path


def interruptible() -> None:
    """For a child process a test stops with SIGINT: Ctrl-C reaches it even when the tests run
    as a shell's background job (which starts them, and so their children, with SIGINT
    ignored)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
