"""A tree runner serving a mode file in-process, for the monitor's Modes tests.

Every mode's tree is `Sequence` (id `root`) → `Scripted` (id `act`, RUNNING): the trees share
their node ids, as behavior3editor 1.x trees do, so a status of the tree left that were shown on
the tree entered would be seen. `mode_file(n)` declares `n` modes (`normal`, `low`, `critical`,
`demo`, then `mode_5` …), each reachable.
"""

from __future__ import annotations

import itertools
from pathlib import Path

from cyborg.bt import ManualClock
from cyborg.bus import Context, Node
from cyborg.runner.tree_runner import TreeRunnerNode
from tests.builders import N, project_json, registry, tree_json

NAMESPACE = "/cyborg/bt"
FIRST = ["normal", "low", "critical", "demo"]
TITLES = {"normal": "Patrol", "low": "Go charge", "critical": "Stop and call", "demo": "Demo"}


def mode_names(count: int) -> list[str]:
    """The names of ``count`` modes: the mission's four, then ``mode_5`` …"""
    return (FIRST + [f"mode_{n}" for n in range(5, count + 1)])[:count]


def title_of(mode: str) -> str:
    """The title of ``mode``'s tree."""
    return TITLES.get(mode, f"Tree of {mode.replace('_', ' ')}")


def write_project(folder: Path, modes: list[str]) -> None:
    """One tree per mode, all with the node ids ``root`` and ``act``."""
    trees = [tree_json(N("Sequence", N("Scripted", script="R", id="act"), id="root"),
                       tree_id=f"tree_{mode}", title=title_of(mode)) for mode in modes]
    (folder / "mission.b3.json").write_text(project_json(trees))


def mode_file(count: int = 4) -> str:
    """A mode file of ``count`` modes (at least 4): conditions, an event, a request, a time."""
    names = mode_names(count)
    lines = ['project = "mission.b3.json"', 'initial = "normal"']
    for mode in names:
        lines += [f"[modes.{mode}]", f'tree = "{title_of(mode)}"']
        if mode == "demo":
            lines += ["max_time = 60", 'then = "normal"']
    lines += ['[[transitions]]', 'from = "*"', 'to = "critical"',
              'when = "battery.percent < 5 && !charging"', 'reason = "battery critical"',
              '[[transitions]]', 'from = "normal"', 'to = "low"',
              'when = "battery.percent < 20"',
              '[[transitions]]', 'from = "low"', 'to = "normal"',
              'when = "battery.percent >= 95"',
              '[[transitions]]', 'from = "critical"', 'to = "normal"',
              'event = "help_arrived"',
              '[[transitions]]', 'from = ["normal", "low"]', 'to = "demo"', 'on_request = true']
    for previous, mode in itertools.pairwise(names[3:]):
        lines += ['[[transitions]]', f'from = "{previous}"', f'to = "{mode}"',
                  f'event = "next_{mode}"']
    return "\n".join(lines) + "\n"


def write_modes(folder: Path, count: int = 4) -> Path:
    """The project and its mode file of ``count`` modes in ``folder``; the mode file."""
    write_project(folder, mode_names(count))
    path = folder / "mission.modes.toml"
    path.write_text(mode_file(count))
    return path


def start_runner(bus: Context, folder: Path, count: int = 4, *,
                 enabled: bool = False) -> TreeRunnerNode:
    """A runner of the mode file of ``count`` modes on a ManualClock, paused unless
    ``enabled``; the battery full."""
    runner = TreeRunnerNode(Node("tree_runner", NAMESPACE, context=bus),
                            write_modes(folder, count), registry=registry(),
                            clock=ManualClock(), enabled=enabled)
    runner.tree.blackboard.globals["battery"] = {"percent": 80}
    runner.start()
    return runner
