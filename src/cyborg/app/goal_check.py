"""A launched system's trees drive to goals of its simulated map, or it does not run.

A tree drawn for one map (``MoveTo room1`` on AMROffice.map) started on another (``cyborg up
--tree FILE`` without ``--map``: the campus) would run and fail each MoveTo with a warning that
scrolls away. Once the launch has started, :func:`unknown_goals` compares every ``MoveTo``'s
``location`` in the launch's trees (every mode's tree of a mode file) with the goals of the map
the launch simulates, and names each one that is not there:

    patrol.b3.json: 2 MoveTos drive to goals not on campus.map (its goals: Charger, …); give
    the tree's map with --map:
      tree 'Patrol tree', node 'MoveTo room1' (id 3f2…): no goal 'room1'
      tree 'Patrol tree', node 'MoveTo room2' (id 9a0…): no goal 'room2'

Launches without a simulator (a real robot's map is its own) are not checked.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

from cyborg.app.launch import Launch
from cyborg.bt.tree import Tree
from cyborg.modes import ModeMachine
from cyborg.nav.arnl_map import ArnlMap
from cyborg.robot.move_to import MoveTo
from cyborg.runner.component import RunningTree
from cyborg.sim.component import RunningFleet, RunningSimulator

LISTED = 8
"""Goals of the map named in a line before "…"."""


def unknown_goals(launch: Launch) -> list[str]:
    """For each tree file, a line and then one per MoveTo whose goal the simulated map lacks."""
    maps = [_map_of(item) for item in launch.running
            if isinstance(item, RunningSimulator | RunningFleet)]
    if len(maps) != 1:
        return []
    arnl_map = maps[0]
    names = [item.name for item in arnl_map.goals()]
    known = set(names)
    listed = ", ".join(names[:LISTED]) + (", …" if len(names) > LISTED else "")
    lines = []
    for item in launch.running:
        if not isinstance(item, RunningTree):
            continue
        missing = [f"  tree {tree.title!r}, node {node.label!r} (id {node.uid}): no goal "
                   f"{node.location!r}" for tree in _trees(item) for node in tree
                   if isinstance(node, MoveTo) and node.location not in known]
        if missing:
            count = len(missing)
            lines += [f"{item.runner.path.name}: {count} MoveTo{'s' if count != 1 else ''} "
                      f"drive{'' if count != 1 else 's'} to goals not on "
                      f"{Path(arnl_map.source).name} (its goals: {listed or 'none'}); give the "
                      "tree's map with --map:", *missing]
    return lines


def _map_of(item: RunningSimulator | RunningFleet) -> ArnlMap:
    if isinstance(item, RunningFleet):
        return item.fleet.simulators[0].map
    return item.loop.simulator.map


def _trees(item: RunningTree) -> Iterable[Tree]:
    ticked = item.runner.ticked
    return ticked.trees.values() if isinstance(ticked, ModeMachine) else [ticked]
