"""End to end in simulated time: the bundled mission greets a person on its patrol and drives on.

The simulator of the campus (with the simulated camera), the tracker and the tree runner of
campus.modes.toml, as ``cyborg up`` wires them, on an isolated bus. One person walks to and fro
beside the way into the courtyard, the third goal of the round, so the robot meets them on its
third leg: it turns toward them, says hello on ``/cyborg/say`` once (not again within the
cooldown, though it sees them again on its way on), and drives on to the courtyard — the goal
it was driving to, not the first of its round.
"""

from __future__ import annotations

import math
import threading
from pathlib import Path

import pytest

from cyborg.app.up import CAMPUS_MAP, CAMPUS_MODES, DATA
from cyborg.bt import SUCCESS
from cyborg.bt.snapshot import TickSnapshot
from cyborg.bus.actions import GoalStatus
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.interfaces import perception, robot
from cyborg.modes import ModeMachine
from tests.running_system import System, running_system, wait_until

WAIT = 90.0
"""Wall seconds any one step may take on a loaded machine (the whole test takes about 30)."""
PERSON = 'Cairn: Sim.Person 24000 8000 0 "24000 8000; 24000 8600" ICON "walker"'
"""Someone pacing beside the way into the courtyard: 1 to 1.6 m from it, 2 m before its goal."""
COURTYARD = (26.0, 7.0)
"""Where the courtyard's goal is on the campus map (m)."""
COOLDOWN = 60.0
"""The bundled tree's OncePerObject ``seconds``: the same person is not greeted again."""
HELLO = "Hello! I am the campus robot."
FACING = 0.5
"""How far (rad) the robot's heading may be from the person's true bearing when it greets:
FaceObject turns to within 0.15 rad of where the tracker puts them, which may be some tenths
of a metre from where they are (noise, the filter's lag behind a person who moves, the robot's
pose while it turns) — at 1.5 to 2 m up to 0.35 rad more."""
SPEED = 4.0
"""The simulation's pace: faster, the poses the tracker places detections from lag the robot's
turn by more than the facing allows."""


class Watch:
    """What the robot says on ``/cyborg/say``; on the tick thread (at the tick's simulated
    time): the patrol's step each tick, the person's true distance when the robot began to turn
    toward them, and where the robot and the person truly were when ``Say`` succeeded."""

    def __init__(self, system: System, machine: ModeMachine) -> None:
        self.system = system
        self.lock = threading.Lock()
        self.said: list[str] = []
        self.greetings: list[tuple[float, float, float]] = []
        """Per greeting: ``(sim time, robot's heading error to the person, distance to them)``."""
        self.steps: list[str] = []
        """The running leaf of each tick when it changed; ``Say`` where the greeting was said."""
        self.turns: list[float] = []
        """The person's true distance each time the robot began to turn toward them."""
        tree = machine.trees["normal"]
        self._labels = {node.uid: node.label for node in tree}
        self._say = next(node.uid for node in tree if node.name == "Say")
        perception.SAY.subscription(system.client, self._heard, robot.NAMESPACE)
        system.runner.runner.add_listener(self._ticked)

    def _heard(self, message: String) -> None:
        with self.lock:
            self.said.append(message.data)

    def _ticked(self, snapshot: TickSnapshot) -> None:
        leaf = self._labels.get(snapshot.active[-1], "") if snapshot.active else ""
        greeted = (self._say, SUCCESS) in snapshot.visited
        sim = self.system.sim
        crowd = sim.crowd
        assert crowd is not None
        pose, people, now = sim.pose, crowd.positions, sim.time
        x, y = float(people[0][0]), float(people[0][1])
        distance = math.hypot(x - pose.x, y - pose.y)
        with self.lock:
            if greeted:
                self.steps.append("Say")
                bearing = math.atan2(y - pose.y, x - pose.x)
                error = abs(math.remainder(bearing - pose.theta, 2 * math.pi))
                self.greetings.append((now, error, distance))
            if leaf and (not self.steps or self.steps[-1] != leaf):
                self.steps.append(leaf)
                if leaf == "Face the person":
                    self.turns.append(distance)

    def seen(self) -> tuple[list[tuple[float, float, float]], list[str], list[str],
                            list[float]]:
        """The greetings, steps, sentences and turns so far."""
        with self.lock:
            return list(self.greetings), list(self.steps), list(self.said), list(self.turns)


def _at(system: System, goal: tuple[float, float]) -> bool:
    """Whether the robot stands within MoveTo's radius (0.5 m) of ``goal``."""
    pose = system.sim.pose
    return math.hypot(pose.x - goal[0], pose.y - goal[1]) < 0.5


@pytest.mark.heavy
def test_the_patrol_greets_a_person_it_meets_once_and_drives_on(tmp_path: Path) -> None:
    campus = Path(str(DATA.joinpath(CAMPUS_MAP))).read_text()
    map_path = tmp_path / "campus.map"
    map_path.write_text(campus.replace("\nLINES\n", f"\n{PERSON}\nLINES\n", 1))
    mode_file = Path(str(DATA.joinpath(CAMPUS_MODES)))
    with running_system(map_path, mode_file, speed=SPEED, tracker=True,
                        sim_parameters={"camera": True, "people": 0}) as system:
        machine = system.runner.ticked
        assert isinstance(machine, ModeMachine)
        watch = Watch(system, machine)
        wait_until(lambda: watch.seen()[0], WAIT, "a greeting")
        greeted_at = watch.seen()[0][0][0]
        wait_until(lambda: _at(system, COURTYARD), WAIT, "the courtyard after the greeting")
        goals = system.goals()
        wait_until(lambda: system.sim.time > greeted_at + COOLDOWN, WAIT,
                   "the cooldown after the greeting")
        wait_until(lambda: watch.seen()[2], WAIT, "the greeting on /cyborg/say")
        greetings, steps, said, turns = watch.seen()
        assert machine.mode == "normal"

    assert said[0] == HELLO
    _, facing, distance = greetings[0]
    assert turns[0] < 2.5, "the robot turned to a person near (2 m by the tracker's estimate)"
    assert distance < 3.5, "and greeted them while they stood or walked by"
    assert facing < FACING, f"the robot faced the person when it greeted ({facing:.2f} rad off)"
    within = [greeting for greeting in greetings if greeting[0] < greeted_at + COOLDOWN]
    assert len(within) == 1, f"one greeting for the one person within the cooldown: {within}"
    # the patrol was driving to the courtyard; the greeting turned the robot; the patrol went on
    greeting = steps.index("Say")
    before = [step for step in steps[:greeting] if step.startswith(("MoveTo", "Wait"))]
    after = [step for step in steps[greeting:] if step.startswith(("MoveTo", "Wait"))]
    assert before[-1] == "MoveTo Courtyard", steps[:greeting]
    assert "Face the person" in steps[:greeting], "it turned toward them first"
    assert after[0] == "MoveTo Courtyard", "the round resumed at the goal it was driving to"
    names = [name for name, _ in goals]
    rounds = [name for k, name in enumerate(names) if k == 0 or names[k - 1] != name]
    assert rounds[:3] == ["Lecture hall", "Library", "Courtyard"], names
    courtyard = [status for name, status in goals if name == "Courtyard"]
    assert len(courtyard) >= 2, "the halted MoveTo's goal was sent again"
    assert courtyard[0] is not GoalStatus.SUCCEEDED, "the greeting cancelled the goal it halted"
