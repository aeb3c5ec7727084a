"""Helpers for the mode tests: an editor project of Scripted trees and mode files beside it.

`write_project` writes a behavior3editor 0.3.0 project whose trees are each one `Scripted`
action (tree id = title = the name given, script as given: "R" keeps it RUNNING), so a mode's
tree halts visibly: every Scripted node logs its lifecycle into the global `events` list.
"""

from __future__ import annotations

from pathlib import Path

from cyborg.bt import Blackboard, ManualClock
from cyborg.modes import ModeMachine, load_machine
from tests.builders import N, project_json, registry, tree_json

PROJECT = "mission.b3.json"


def write_project(folder: Path, scripts: dict[str, str], name: str = PROJECT) -> Path:
    """A project with one tree per entry: id and title the key, one Scripted (tag = key)."""
    trees = [tree_json(N("Scripted", script=script, tag=tree), tree_id=tree, title=tree)
             for tree, script in scripts.items()]
    path = folder / name
    path.write_text(project_json(trees))
    return path


def write_modes(folder: Path, text: str, name: str = "mission.modes.toml") -> Path:
    path = folder / name
    path.write_text(text)
    return path


def machine(folder: Path, text: str, scripts: dict[str, str],
            clock: ManualClock | None = None) -> ModeMachine:
    """The machine of mode file `text` over a project of `scripts`, on a ManualClock at 0."""
    write_project(folder, scripts)
    return load_machine(write_modes(folder, text), registry=registry(),
                        clock=clock or ManualClock(), blackboard=Blackboard({"events": []}))


def events(m: ModeMachine) -> list[tuple[str, str]]:
    """The Scripted nodes' lifecycle log since the last call."""
    log: list[tuple[str, str]] = m.globals["events"]
    copy = list(log)
    log.clear()
    return copy
