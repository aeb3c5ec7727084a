"""From a mode file to a running :class:`~cyborg.modes.machine.ModeMachine`, all or nothing.

:func:`load_machine` reads and checks the file (:mod:`cyborg.modes.mode_file`), then builds
every mode's tree with the engine's loader (:func:`cyborg.bt.load_tree`), from one registry and
on one clock. Each tree gets a blackboard of its own whose global scope and resources are those
of the blackboard given (so a value written in one mode is read in the next, and the robot's
handle reaches every tree), while its tree and node scopes stay its own.

A tree that does not build (an unknown node, a bad property) is reported with the problems of
every other mode, and no machine is made: nothing half-starts.
"""

from __future__ import annotations

from pathlib import Path

from cyborg.bt.blackboard import Blackboard
from cyborg.bt.clock import Clock
from cyborg.bt.loader import load_tree
from cyborg.bt.problems import Problem, TreeLoadError
from cyborg.bt.registry import NodeRegistry
from cyborg.bt.service_registry import ServiceRegistry
from cyborg.bt.status import Status
from cyborg.bt.tree import Tree
from cyborg.modes.machine import ModeMachine
from cyborg.modes.mode_file import ModeFileError, read_mode_file
from cyborg.modes.spec import MachineSpec


def load_machine(path: str | Path, *, registry: NodeRegistry | None = None,
                 clock: Clock | None = None, blackboard: Blackboard | None = None,
                 stub_missing: Status | None = None,
                 services: ServiceRegistry | None = None) -> ModeMachine:
    """Reads the mode file at ``path`` and builds its machine; :class:`ModeFileError` if bad.

    ``registry``, ``services``, ``clock`` and ``stub_missing`` are passed to every
    :func:`~cyborg.bt.load_tree`; ``blackboard`` gives the shared global scope and resources.
    """
    return build_machine(read_mode_file(path), registry=registry, clock=clock,
                         blackboard=blackboard, stub_missing=stub_missing, services=services)


def build_machine(spec: MachineSpec, *, registry: NodeRegistry | None = None,
                  clock: Clock | None = None, blackboard: Blackboard | None = None,
                  stub_missing: Status | None = None,
                  services: ServiceRegistry | None = None) -> ModeMachine:
    """Builds the tree of every mode of ``spec`` and the machine over them."""
    shared = blackboard if blackboard is not None else Blackboard()
    trees: dict[str, Tree] = {}
    problems: list[Problem] = []
    for name, mode in spec.modes.items():
        own = Blackboard(resources={})
        own.globals, own.resources = shared.globals, shared.resources
        try:
            trees[name] = load_tree(mode.project, tree=mode.tree, registry=registry,
                                    clock=clock, blackboard=own, stub_missing=stub_missing,
                                    services=services)
        except TreeLoadError as exc:
            problems.append(Problem(f"mode {name!r}: its tree {mode.tree!r} does not load "
                                    "(the problems follow)", spec.source, mode.line,
                                    field="tree"))
            problems.extend(exc.problems)
    if problems:
        raise ModeFileError(problems)
    return ModeMachine(spec, trees, clock=clock)
