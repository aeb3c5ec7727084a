"""End to end: the bundled mission on modes (`cyborg up`'s) goes through every one of its modes.

The simulator and the tree runner of campus.modes.toml, in one process on simulated time as fast
as the machine allows, from a 31 % charge: the patrol (normal) runs until the battery falls
below 30 %; the machine leaves it — halting the patrol, so a running MoveTo cancels its goal —
for low_battery, which drives to the charger and charges; at 60 % it patrols again. A request
(`cyborg bt mode demo`, here the mode/set service) starts the demo, which ends on its time
limit. An `emergency` event, sent while the robot drives, stops it in critical: the goal in
progress is cancelled (or dropped by the stop), the robot stands still and calls for help on
/cyborg/help, until `help_arrived` sends it back to patrol.
"""

from __future__ import annotations

import threading
import time
from pathlib import Path

import pytest

from cyborg.app.up import CAMPUS_MAP, CAMPUS_MODES, DATA
from cyborg.bt.snapshot import TickSnapshot
from cyborg.bus.actions import GoalStatus
from cyborg.bus.msgs.cyborg_msgs.msg import ModeTransition
from cyborg.bus.msgs.cyborg_msgs.srv import SetMode
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.interfaces import modes
from cyborg.interfaces.help import HELP, HelpCall, read_help
from cyborg.interfaces.modes import ModeAction
from cyborg.modes import ModeMachine, Transition
from cyborg.robot.settling_robot import SettlingBusRobot
from cyborg.runner.component import RunningTree
from tests.running_system import System, running_system, wait_until

TREES = "/cyborg/bt"
WAIT = 90.0
"""Wall seconds any one step may take on a loaded machine (each takes a few)."""


class Watch:
    """What the test hears on the bus: transitions and calls for help."""

    def __init__(self, system: System) -> None:
        self.lock = threading.Lock()
        self.transitions: list[ModeTransition] = []
        self.help: list[HelpCall] = []
        client = system.client
        modes.TRANSITIONS.subscription(client, self._transition, TREES)
        HELP.subscription(client, self._help, "/cyborg")
        self.events = modes.EVENTS.publisher(client, TREES)
        self.set_mode = modes.SET_MODE.client(client, TREES)

    def _transition(self, message: ModeTransition) -> None:
        with self.lock:
            self.transitions.append(message)

    def _help(self, message: String) -> None:
        with self.lock:
            self.help.append(read_help(message))

    def fire(self, machine: ModeMachine, event: str, until: str) -> None:
        """Publishes ``event`` (again every half second until heard) until the mode is ``until``."""
        sent: list[float] = []

        def taken() -> bool:
            if not sent or time.monotonic() - sent[-1] > 0.5:
                sent.append(time.monotonic())
                self.events.publish(String(data=event))
            return machine.mode == until

        wait_until(taken, WAIT, f"the event {event!r} to lead to {until}")


@pytest.mark.heavy
def test_the_bundled_mission_goes_through_every_mode() -> None:
    mode_file = Path(str(DATA.joinpath(CAMPUS_MODES)))
    campus = Path(str(DATA.joinpath(CAMPUS_MAP)))
    with running_system(campus, mode_file, speed=0, battery=31.0) as system:
        runner = system.runner
        machine = runner.ticked
        assert isinstance(machine, ModeMachine)
        watch = Watch(system)
        labels = {node.uid: node.label for tree in machine.trees.values() for node in tree}
        driving: list[str] = []  # the node running at the end of the latest tick

        def follow(snapshot: TickSnapshot) -> None:
            driving[:] = [labels.get(uid, "") for uid in snapshot.active[-1:]]

        runner.runner.add_listener(follow)
        robot = next(item for item in system.launch.running
                     if isinstance(item, RunningTree)).robot
        assert isinstance(robot, SettlingBusRobot)
        left_running: list[str] = []  # what ran when the machine left normal for critical
        cancelled: list[str] = []  # the goals whose cancel the halt sent

        def left(transition: Transition) -> None:  # runs once the old tree has halted
            if transition.target == "critical":
                left_running.extend(driving[:1])
                cancelled.extend(move.goal for move in robot._moves if move._cancel_sent)

        machine.add_listener(left)

        # normal -> low_battery as the battery drains, -> normal once charged
        wait_until(lambda: machine.transition_count >= 2 and machine.mode == "normal", WAIT,
                   "low_battery, then normal again")
        assert system.sim.battery.charge_percent >= 60.0
        assert system.sim.docking.docks >= 1, "it charged on the dock"

        # demo by a request, left on its time limit
        assert watch.set_mode.wait_for_service(10.0)

        def demo_taken() -> bool:  # refused while normal has not run its min_dwell
            reply = watch.set_mode.call(SetMode.Request(
                action=int(ModeAction.REQUEST), mode="demo", reason="visitors"), timeout=10.0)
            return bool(reply.success)

        wait_until(demo_taken, WAIT, "the demo request to be taken")
        wait_until(lambda: machine.mode == "normal", WAIT, "the demo's end")

        # critical on an emergency while the robot drives: stopped, calling for help
        wait_until(lambda: driving[:1] != [] and driving[0].startswith("MoveTo "), WAIT,
                   "the patrol to drive")
        watch.fire(machine, "emergency", "critical")
        wait_until(lambda: bool(watch.help), WAIT, "a call for help")
        stopped_at = system.sim.time
        wait_until(lambda: system.sim.time > stopped_at + 60.0, WAIT, "a simulated minute")
        goals_in_critical = system.goals()
        watch.fire(machine, "help_arrived", "normal")
        wait_until(lambda: len(watch.transitions) >= 6, WAIT, "every transition on the bus")

    with watch.lock:
        heard = [(t.from_mode, t.to_mode, t.trigger, t.reason) for t in watch.transitions]
        calls = list(watch.help)
    assert heard[:6] == [
        ("normal", "low_battery", "condition", "battery low (below 30 %)"),
        ("low_battery", "normal", "condition", "charged (60 %)"),
        ("normal", "demo", "request", "visitors"),
        ("demo", "normal", "timeout", heard[3][3]),
        ("normal", "critical", "event", "emergency"),
        ("critical", "normal", "event", "help arrived")]
    assert "600" in heard[3][3], "the demo's time limit says its time"
    assert [t.source for t in machine.history][:6] == [h[0] for h in heard[:6]]

    # leaving normal for critical halted the patrol: its MoveTo sent the cancel of its goal,
    # which the navigator dropped (CANCELED, or ABORTED when StopSafely's stop came first) —
    # unless the robot arrived just then (or the Wait after a move was halted)
    assert left_running and left_running[0].startswith(("MoveTo ", "Wait ")), left_running
    if left_running[0].startswith("MoveTo "):
        goal = left_running[0].removeprefix("MoveTo ")
        ended = [status for name, status in goals_in_critical if name == goal][-1]
        if ended is not GoalStatus.SUCCEEDED:
            assert goal in cancelled, (goal, cancelled)
            assert ended in (GoalStatus.CANCELED, GoalStatus.ABORTED), ended
    assert all(status.terminal for _, status in goals_in_critical), \
        "stopped: no goal under way in critical"
    # the call for help: the robot, where it stands, its charge, and why
    call = calls[0]
    assert call.robot == "/cyborg" and call.pose is not None and call.battery is not None
    assert call.reason.startswith("critical: stopped")
    assert "; near " in call.reason, "ClosestGoal, a service of the patrol, said where it is"
    assert call.battery > 30.0, "an emergency, not the battery"
