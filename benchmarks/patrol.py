"""The benchmarks' patrol: the robot drives to the map's goals in turn until a simulated time.

    reached = patrol_goals(sim, end=sim.time + 600, step=step)   # goals reached in 10 min

``step`` advances the simulation one physics step (default ``sim.step``; a benchmark that
takes camera frames or measures errors between steps passes its own). A goal that cannot be
planned to is passed over.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable

from cyborg.sim.navigator import PathState
from cyborg.sim.simulator import Simulator


def patrol_goals(sim: Simulator, end: float, step: Callable[[], None] | None = None) -> int:
    """Drive to the map's goals in turn until ``sim.time`` reaches ``end``; goals reached."""
    advance = step or sim.step
    names = [item.name for item in sim.map.goals()]
    reached = 0
    for name in itertools.cycle(names):
        if sim.time >= end:
            break
        if sim.go_to(name).found:
            while not sim.navigator.state.finished and sim.time < end:
                advance()
            reached += sim.navigator.state is PathState.REACHED_GOAL
    return reached
