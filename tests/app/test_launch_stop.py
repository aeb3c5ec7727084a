"""How `cyborg launch` stops: tree runners first, so a running MoveTo cancels its goal while the
robot's nodes are still there; then the process's other nodes; then the child processes."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
from pathlib import Path
from typing import Any, cast

import pytest

from cyborg.app.launch import Launch, LaunchDescription
from cyborg.bus import BusConfig, Context, GoalStatus, Node, Qos
from cyborg.runner.component import RunningTree
from tests.app.test_launch import _launch_file
from tests.ports import free_port
from tests.running_system import interruptible, wait_until


class FakeNode:
    """A started node that notes when it is stopped."""

    def __init__(self, name: str, log: list[str]) -> None:
        self.name, self.log = name, log

    def describe(self) -> str:
        return f"{self.name}  /cyborg/{self.name}: details"

    def stop(self) -> None:
        self.log.append(self.name)


class FakeTree(FakeNode, RunningTree):
    """A tree runner handle (the launch stops these first) without a tree."""

    def __init__(self, name: str, log: list[str]) -> None:
        FakeNode.__init__(self, name, log)


class FakeChild:
    """A child process that ends when signalled, noting the signal."""

    def __init__(self, name: str, log: list[str]) -> None:
        self.name, self.log, self.pid = name, log, 0
        self.returncode: int | None = None

    def poll(self) -> int | None:
        return self.returncode

    def send_signal(self, signum: int) -> None:
        self.log.append(f"{self.name} {signal.Signals(signum).name}")
        self.returncode = 130

    def wait(self, timeout: float | None = None) -> int:
        assert self.returncode is not None, f"{self.name} was waited for before it was signalled"
        self.log.append(f"{self.name} ended")
        return self.returncode

    def kill(self) -> None:
        self.log.append(f"{self.name} killed")


def test_stop_halts_trees_first_then_other_nodes_then_children_in_reverse() -> None:
    log: list[str] = []
    launch = Launch(LaunchDescription([]), cast(Context, None))
    launch.running = [FakeNode("monitor", log), FakeNode("simulator", log),
                      FakeTree("tree_runner", log), FakeNode("detector", log),
                      FakeTree("second_tree", log)]
    launch.children = [(name, cast(subprocess.Popen[bytes], FakeChild(name, log)))
                       for name in ("robot", "vision")]
    launch.stop()
    assert log == ["second_tree", "tree_runner",            # trees halt, in reverse start order
                   "detector", "simulator", "monitor",      # then the others, in reverse
                   "vision SIGTERM", "vision ended",        # then each child, the last first,
                   "robot SIGTERM", "robot ended"]          # each gone before the next is asked
    assert launch.running == []


class GoalWatcher:
    """Follows the statuses of the robot's move_to_goal goals, from the test's own bus node."""

    def __init__(self, endpoint: str) -> None:
        self.context = Context(BusConfig.from_environment([endpoint]))
        self.node = Node("goal_watcher", "/test", context=self.context)
        self.statuses: dict[bytes, GoalStatus] = {}
        self.order: list[bytes] = []
        self._lock = threading.Lock()
        self.node.create_subscription("/cyborg/move_to_goal/_action/status",
                                      "action_msgs/msg/GoalStatusArray", self._on_status,
                                      Qos.latched(depth=1))

    def _on_status(self, message: Any) -> None:
        with self._lock:
            for entry in message.status_list:
                goal = bytes(entry.goal_info.goal_id.uuid)
                if goal not in self.statuses:
                    self.order.append(goal)
                self.statuses[goal] = GoalStatus(entry.status)

    def executing(self) -> bool:
        with self._lock:
            return GoalStatus.EXECUTING in self.statuses.values()

    def last(self) -> GoalStatus:
        with self._lock:
            return self.statuses[self.order[-1]]

    def close(self) -> None:
        self.node.destroy()
        self.context.close()


@pytest.mark.heavy
@pytest.mark.parametrize("ctrl_c", ["to the launch process", "to the terminal's process group"])
def test_ctrl_c_halts_the_tree_before_the_simulator_process_goes(
        tmp_path: Path, shared: Path, ctrl_c: str) -> None:
    """The README's launch example: the simulator in process "robot", the tree runner in main.
    Ctrl-C in a terminal reaches every process of the job; the launch alone decides the order."""
    port = free_port()
    path = _launch_file(tmp_path, shared, port=port, process="robot")
    parent = subprocess.Popen([sys.executable, "-m", "cyborg", "-v", "launch", str(path)],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              env=dict(os.environ, PYTHONUNBUFFERED="1"),
                              preexec_fn=interruptible, start_new_session=True)
    watcher = GoalWatcher(f"tcp/127.0.0.1:{port}")
    try:
        wait_until(watcher.executing, timeout=90, what="the robot to move")
        if ctrl_c == "to the launch process":
            parent.send_signal(signal.SIGINT)
        else:
            os.killpg(parent.pid, signal.SIGINT)
        output = parent.communicate(timeout=60)[0]
        last = watcher.last()  # the simulator published its goal's end before its process went
    finally:
        if parent.poll() is None:
            os.killpg(parent.pid, signal.SIGKILL)
        watcher.close()
    assert parent.returncode == 130, output
    assert last is GoalStatus.CANCELED, f"the running move ended {last.name}:\n{output}"
    for bad in ("cancel", "WARNING", "ERROR", "Traceback"):
        assert bad not in output.replace("CANCELED", ""), output
    stopping = [line.split("stopping ", 1)[1] for line in output.splitlines()
                if "cyborg.app: stopping " in line]
    assert [part.split()[0] for part in stopping] == ["tree", "process", "simulator"], output
    assert stopping[0].startswith("tree runner /cyborg/bt/tree_runner")
    assert stopping[1].startswith("process robot (pid")
    assert stopping[2].startswith("simulator /cyborg/arnl")  # logged by the child
