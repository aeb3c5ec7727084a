"""The tree runner's services never wait on each other: a reload that hangs or takes long runs in
the background with a timeout, and the control services (enable above all: the stop button)
answer on a thread of their own. On an isolated bus with a scripted robot, no simulator."""

from __future__ import annotations

import errno
import os
import threading
import time
from collections.abc import Iterator
from concurrent.futures import Future
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest

from cyborg.bt import Action, NodeRegistry, Status, default_registry
from cyborg.bus import BusConfig, Context, Node, Qos, new_message
from cyborg.bus.executor import CallbackThread
from cyborg.robot.protocol import DockState
from cyborg.runner.tree_runner import TreeRunnerNode
from tests.robot.fake_robot import FakeRobot
from tests.running_system import wait_until, write_tree

GATES: dict[str, threading.Event] = {}
"""Slow nodes wait in their constructor until the test opens their gate."""


class SlowToBuild(Action):
    """A node whose constructor takes as long as the test says (a model that loads slowly)."""

    def __init__(self, gate: str = "") -> None:
        GATES[gate].wait(30.0)

    def tick(self) -> Status:
        return Status.RUNNING


def slow_registry() -> NodeRegistry:
    registry = default_registry()
    registry.add(SlowToBuild)
    return registry


@pytest.fixture
def bus() -> Iterator[Context]:
    context = Context(BusConfig.isolated())
    yield context
    context.close()


@contextmanager
def runner_on(bus: Context, tree: Path, robot: FakeRobot, **options: Any) -> Iterator[
        TreeRunnerNode]:
    runner = TreeRunnerNode(Node("tree_runner", "/cyborg/bt", context=bus), tree, robot=robot,
                            registry=slow_registry(), **options)
    runner.start()
    try:
        yield runner
    finally:
        runner.destroy()


class Caller:
    """A client of the runner's services, as the monitor or ``cyborg service call`` is."""

    def __init__(self, bus: Context) -> None:
        self.node = Node("tester", "/test", context=bus)

    def call_async(self, name: str, service: str, timeout: float = 10.0,
                   **fields: Any) -> Future[Any]:
        client = self.node.create_client(f"/cyborg/bt/{name}", service)
        assert client.wait_for_service(5.0), name
        request = new_message(self.node.types, f"{service}_Request", fields)
        return client.call_async(request, timeout)

    def call(self, name: str, service: str, timeout: float = 10.0, **fields: Any) -> Any:
        return self.call_async(name, service, timeout, **fields).result(timeout + 1.0)

    def timed(self, name: str, service: str, timeout: float = 3.0,
              **fields: Any) -> tuple[Any, float]:
        """The reply and the wall seconds it took."""
        started = time.monotonic()
        reply = self.call(name, service, timeout, **fields)
        return reply, time.monotonic() - started


def release_fifo(fifo: Path, within: float = 2.0) -> None:
    """Unblock whoever opened ``fifo`` for reading: open it for writing and close it, so the
    reader sees the end of the file and no thread stays parked. Nobody opened it: nothing."""
    deadline = time.monotonic() + within
    while True:
        try:
            descriptor = os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)
        except OSError as exc:
            if exc.errno != errno.ENXIO or time.monotonic() > deadline:
                return  # no reader: nothing is blocked on it
            time.sleep(0.01)
            continue
        os.close(descriptor)
        return


def refused_or_timed_out(message: str, timeout: str) -> bool:
    """A reload of a FIFO: refused by the loader (not a regular file) or, where a loader
    opens it anyway, answered when the timeout is up."""
    return "not a regular file" in message or f"did not finish within {timeout}" in message


def test_enable_answers_at_once_while_a_reload_hangs_on_a_fifo(bus: Context,
                                                               tmp_path: Path) -> None:
    robot = FakeRobot()
    tree = write_tree(tmp_path, {"name": "MoveTo", "props": {"location": "home"}})
    fifo = tmp_path / "hangs.b3.json"
    os.mkfifo(fifo)
    with runner_on(bus, tree, robot, reload_timeout=1.5) as runner:
        caller = Caller(bus)
        wait_until(lambda: robot.moves, timeout=5, what="the robot to be sent home")
        reload = caller.call_async("reload", "cyborg_msgs/srv/ReloadTree", path=str(fifo))
        try:
            time.sleep(0.3)  # the reload is under way: opening the FIFO blocks
            reply, took = caller.timed("enable", "std_srvs/srv/SetBool", data=False)
            assert (reply.success, reply.message) == (True, "disabled")
            assert took < 1.0, f"enable took {took:.2f} s behind a hanging reload"
            assert robot.moves[0].cancelled, "disabling halted MoveTo: the robot stops"
            assert not runner.enabled
            answer = reload.result(5.0)
            assert not answer.success
            assert refused_or_timed_out(answer.message, "1.5 s"), answer.message
            assert runner.path == tree, "the old tree is still the one loaded"
        finally:
            release_fifo(fifo)
        assert caller.call("enable", "std_srvs/srv/SetBool", data=True).success
        wait_until(lambda: len(robot.moves) == 2, timeout=5, what="the tree to run again")


def test_a_slow_reload_times_out_keeps_the_old_tree_and_its_late_result_is_dropped(
        bus: Context, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    robot = FakeRobot()
    tree = write_tree(tmp_path, {"name": "MoveTo", "props": {"location": "home"}})
    slow = write_tree(tmp_path, {"name": "SlowToBuild", "props": {"gate": "slow"}}, "slow.b3.json")
    good = write_tree(tmp_path, {"name": "MoveTo", "props": {"location": "kitchen"}},
                      "good.b3.json")
    GATES["slow"] = threading.Event()
    try:
        with runner_on(bus, tree, robot, reload_timeout=1.5) as runner:
            caller = Caller(bus)
            old = runner.tree
            started = time.monotonic()
            pending = caller.call_async("reload", "cyborg_msgs/srv/ReloadTree", path=str(slow))
            time.sleep(0.1)
            # one reload at a time: another one is refused at once, not queued
            busy, took = caller.timed("reload", "cyborg_msgs/srv/ReloadTree", path=str(good))
            assert not busy.success and "still loading" in busy.message and took < 1.0
            # and the stop button answers while the load hangs
            reply, took = caller.timed("enable", "std_srvs/srv/SetBool", data=False)
            assert reply.success and took < 1.0, f"enable took {took:.2f} s"
            assert not pending.done(), "enable was answered while the load hangs"
            answer = pending.result(5.0)
            assert 1.4 < time.monotonic() - started < 3.0
            assert not answer.success
            assert answer.message.startswith("reload timed out:"), answer.message
            assert str(slow) in answer.message and "1.5 s" in answer.message
            assert "reload_timeout" in answer.message and "keeps running" in answer.message
            assert caller.call("enable", "std_srvs/srv/SetBool", data=True).success
            ticks = old.ticks
            wait_until(lambda: old.ticks > ticks + 3, timeout=5, what="the old tree ticking")
            # the load ends after all: its tree must not replace the one the caller was told runs
            GATES["slow"].set()
            wait_until(lambda: "discarded" in caplog.text, timeout=5, what="the late load")
            assert runner.tree is old and runner.path == tree
            # and reloading works again
            reply = caller.call("reload", "cyborg_msgs/srv/ReloadTree", path=str(good))
            assert reply.success, reply.message
            assert runner.path == good and runner.tree is not old
    finally:
        GATES.pop("slow").set()


def test_the_reload_timeout_is_a_parameter(bus: Context, tmp_path: Path) -> None:
    tree = write_tree(tmp_path, {"name": "Runner"})
    node = Node("tree_runner", "/cyborg/bt", context=bus, parameters={"reload_timeout": 7.5})
    runner = TreeRunnerNode(node, tree)
    try:
        assert runner.reload_timeout == 7.5
        node.parameters.set({"reload_timeout": 60.0})
        assert runner.reload_timeout == 60.0
        with pytest.raises(ValueError, match="outside"):
            node.parameters.set({"reload_timeout": 0.0})
    finally:
        runner.destroy()


def test_control_services_answer_while_the_nodes_own_thread_is_busy(bus: Context,
                                                                    tmp_path: Path) -> None:
    """Whatever else the runner's node does (a /clock flood, a parameter callback, a future
    slow handler), enable, step, resume, control and get_blackboard have their own thread."""
    robot = FakeRobot()
    tree = write_tree(tmp_path, {"name": "MoveTo", "props": {"location": "home"}})
    with runner_on(bus, tree, robot) as runner:
        caller = Caller(bus)
        wait_until(lambda: robot.moves, timeout=5, what="the robot to be sent home")
        busy = threading.Event()
        runner.node.callbacks.submit(busy.wait, 10.0)  # the node's own thread is stuck
        try:
            for name, service, fields in (
                    ("get_blackboard", "cyborg_msgs/srv/GetBlackboard", {}),
                    ("step", "std_srvs/srv/Trigger", {}),
                    ("resume", "std_srvs/srv/Trigger", {}),
                    ("control", "cyborg_msgs/srv/ControlNode",
                     {"node_id": "nope", "action": 0}),
                    ("enable", "std_srvs/srv/SetBool", {"data": False})):
                _reply, took = caller.timed(name, service, **fields)
                assert took < 1.0, f"{name} waited {took:.2f} s for the node's thread"
            assert robot.moves[0].cancelled
        finally:
            busy.set()


def test_enable_answers_while_a_tick_waits_for_a_slow_robot(bus: Context,
                                                            tmp_path: Path) -> None:
    """A node blocked in a robot call (the robot's own service thread is busy) holds its tick;
    disabling answers anyway and the halt follows as soon as the tick ends."""
    robot = FakeRobot()
    robot.set_battery(20.0)
    answering = threading.Event()
    asked = threading.Event()

    def slow_dock() -> tuple[bool, str]:
        asked.set()
        answering.wait(10.0)
        robot.dock_requests += 1
        robot.set_battery(20.0, DockState.DOCKING)
        return True, "docking"
    robot.dock = slow_dock  # type: ignore[method-assign]
    tree = write_tree(tmp_path, {"name": "Charge", "props": {"target": 90}})
    with runner_on(bus, tree, robot) as runner:
        caller = Caller(bus)
        try:
            assert asked.wait(5.0), "Charge asked the robot to dock"
            reply, took = caller.timed("enable", "std_srvs/srv/SetBool", data=False)
            assert took < 1.0, f"enable waited {took:.2f} s for the tick"
            assert reply.success and reply.message.startswith("disabled")
            assert "halts when its current tick ends" in reply.message, reply.message
            assert robot.stops == 0, "the tick has not ended: nothing is halted yet"
            # enabling again cannot start while the halt is pending: refused, not held up
            again, took = caller.timed("enable", "std_srvs/srv/SetBool", data=True)
            assert took < 1.0 and not again.success and "still halting" in again.message
            assert not runner.enabled
        finally:
            answering.set()
        # the tick ends, Charge is halted and abandons the drive to the dock
        wait_until(lambda: robot.stops == 1, timeout=5, what="the halt after the tick")
        assert not runner.tree.running
        ticks = runner.tree.ticks
        time.sleep(0.3)
        assert runner.tree.ticks == ticks, "a disabled tree does not tick"
        assert caller.call("enable", "std_srvs/srv/SetBool", data=True).success
        wait_until(lambda: runner.tree.ticks > ticks, timeout=5, what="ticking again")


def test_stop_halts_the_tree_and_says_stopped_until_it_is_enabled(bus: Context,
                                                                  tmp_path: Path) -> None:
    """``stop`` (the monitor's STOP) halts as ``enable(false)`` does and latches ``stopped``,
    which a watcher that comes later reads too; a disable changes nothing of it, an enable
    clears it."""
    robot = FakeRobot()
    tree = write_tree(tmp_path, {"name": "MoveTo", "props": {"location": "home"}})
    with runner_on(bus, tree, robot) as runner:
        caller = Caller(bus)
        watcher = Node("watcher", "/test", context=bus)
        stopped: list[bool] = []
        watcher.create_subscription("/cyborg/bt/stopped", "std_msgs/msg/Bool",
                                    lambda message: stopped.append(message.data), Qos.latched())
        wait_until(lambda: robot.moves and stopped == [False], timeout=5,
                   what="the robot sent home, the runner not stopped")
        reply = caller.call("stop", "std_srvs/srv/Trigger")
        assert reply.success and reply.message.startswith("stopped"), reply.message
        assert runner.stopped and not runner.enabled and robot.moves[0].cancelled
        wait_until(lambda: stopped[-1:] == [True], timeout=5, what="stopped on the bus")
        later: list[bool] = []
        Node("later", "/test", context=bus).create_subscription(
            "/cyborg/bt/stopped", "std_msgs/msg/Bool", lambda message: later.append(message.data),
            Qos.latched())
        wait_until(lambda: later == [True], timeout=5, what="a later watcher to hear it")
        assert caller.call("enable", "std_srvs/srv/SetBool", data=False).success
        assert runner.stopped, "a disable does not make a stopped tree merely paused"
        assert caller.call("enable", "std_srvs/srv/SetBool", data=True).success
        assert not runner.stopped and runner.enabled
        wait_until(lambda: stopped[-1:] == [False] and len(robot.moves) == 2, timeout=5,
                   what="not stopped on the bus, the robot sent home again")


def test_a_routed_owner_runs_its_callbacks_on_its_own_thread() -> None:
    main, own = CallbackThread("/main"), CallbackThread("/own")
    try:
        class Owner:
            def __init__(self) -> None:
                self.threads: list[str] = []

            def __eq__(self, other: object) -> bool:  # unhashable owners are fine too
                return self is other

            def callback(self, done: threading.Event) -> None:
                self.threads.append(threading.current_thread().name)
                done.set()

        owner, other = Owner(), Owner()
        main.route(owner, own)
        stuck = threading.Event()
        main.submit(stuck.wait, 5.0)
        done = threading.Event()
        main.submit(owner.callback, done)
        assert done.wait(1.0), "the routed callback ran although the main thread is busy"
        assert owner.threads == ["cyborg-node/own"]
        later = threading.Event()
        main.submit(other.callback, later)
        assert not later.wait(0.2), "callbacks of other owners still queue on the main thread"
        stuck.set()
        assert later.wait(1.0) and other.threads == ["cyborg-node/main"]
    finally:
        main.close()
        own.close()
