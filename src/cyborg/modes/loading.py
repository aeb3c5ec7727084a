"""From a mode file to a running :class:`~cyborg.modes.machine.ModeMachine`, all or nothing.

:func:`load_machine` reads and checks the file (:mod:`cyborg.modes.mode_file`), then builds
every mode's tree with the engine's loader (:func:`cyborg.bt.load_tree`), from one registry and
on one clock. Each tree gets a blackboard of its own whose global scope and resources are those
of the blackboard given (so a value written in one mode is read in the next, and the robot's
handle reaches every tree), while its tree and node scopes stay its own.

Modes that name the same tree of the same file share one instance of it, built once: only one
mode runs at a time, leaving a mode halts its tree and entering one empties its tree and node
memories, so a tree shared by two modes starts fresh on each entry as two copies would. (What
belongs to the instance rather than to the mode — its hooks, such as breakpoints, and its tick
count — is then the tree's, whichever of those modes runs it.) The trees built hold at most
``max_nodes`` node instances together (:mod:`cyborg.modes.caps`), checked before any is built.

A tree that does not build (an unknown node, a bad property) is reported with the problems of
every other mode, and no machine is made: nothing half-starts.
"""

from __future__ import annotations

from pathlib import Path

from cyborg.bt.blackboard import Blackboard
from cyborg.bt.clock import Clock
from cyborg.bt.loader import load_tree
from cyborg.bt.problems import Problem, TreeLoadError
from cyborg.bt.registry import NodeRegistry, default_registry
from cyborg.bt.service_registry import ServiceRegistry
from cyborg.bt.status import Status
from cyborg.bt.tree import Tree
from cyborg.modes.caps import TreeKey, node_budget, tree_key
from cyborg.modes.machine import ModeMachine
from cyborg.modes.mode_file import ModeFileError, mode_file_limits, read_mode_file
from cyborg.modes.spec import MachineSpec


def load_machine(path: str | Path, *, registry: NodeRegistry | None = None,
                 clock: Clock | None = None, blackboard: Blackboard | None = None,
                 stub_missing: Status | None = None,
                 services: ServiceRegistry | None = None, max_bytes: int | None = None,
                 max_depth: int | None = None, max_nodes: int | None = None) -> ModeMachine:
    """Reads the mode file at ``path`` and builds its machine; :class:`ModeFileError` if bad.

    ``registry``, ``services``, ``clock`` and ``stub_missing`` are passed to every
    :func:`~cyborg.bt.load_tree`; ``blackboard`` gives the shared global scope and resources.
    ``max_bytes``, ``max_depth`` and ``max_nodes`` are the caps of the whole load: the mode
    file, its files and its trees together (:mod:`cyborg.modes.caps`).
    """
    spec = read_mode_file(path, max_bytes=max_bytes, max_depth=max_depth, max_nodes=max_nodes)
    return build_machine(spec, registry=registry, clock=clock, blackboard=blackboard,
                         stub_missing=stub_missing, services=services, max_depth=max_depth,
                         max_nodes=max_nodes)


def build_machine(spec: MachineSpec, *, registry: NodeRegistry | None = None,
                  clock: Clock | None = None, blackboard: Blackboard | None = None,
                  stub_missing: Status | None = None,
                  services: ServiceRegistry | None = None, max_depth: int | None = None,
                  max_nodes: int | None = None) -> ModeMachine:
    """Builds the tree of every mode of ``spec`` (once per different tree) and the machine.

    The trees together may hold at most ``max_nodes`` node instances (left out: as for one
    tree, from ``CYBORG_TREE_MAX_NODES`` or :data:`cyborg.bt.limits.MAX_NODES`).
    """
    limits = mode_file_limits(spec.source, None, max_depth, max_nodes)
    over = node_budget(spec.modes.values(), limits, spec.source)
    if over:
        raise ModeFileError(over)
    registry = default_registry() if registry is None else registry  # read once, not per mode
    shared = blackboard if blackboard is not None else Blackboard()
    built: dict[TreeKey, Tree | None] = {}
    first: dict[TreeKey, str] = {}
    trees: dict[str, Tree] = {}
    problems: list[Problem] = []
    for name, mode in spec.modes.items():
        key = tree_key(mode)
        if key not in built:
            first[key] = name
            own = Blackboard(resources={})
            own.globals, own.resources = shared.globals, shared.resources
            try:
                built[key] = load_tree(mode.project, tree=mode.tree, registry=registry,
                                       clock=clock, blackboard=own, stub_missing=stub_missing,
                                       services=services, max_depth=max_depth,
                                       max_nodes=max_nodes)
            except TreeLoadError as exc:
                built[key] = None
                problems.append(Problem(f"mode {name!r}: its tree {mode.tree!r} does not load "
                                        "(the problems follow)", spec.source, mode.line,
                                        field="tree"))
                problems.extend(exc.problems)
                continue
        tree = built[key]
        if tree is not None:
            trees[name] = tree
        elif first[key] != name:
            problems.append(Problem(f"mode {name!r}: its tree {mode.tree!r} does not load "
                                    f"(the problems are listed with mode {first[key]!r})",
                                    spec.source, mode.line, field="tree"))
    if problems:
        raise ModeFileError(problems)
    return ModeMachine(spec, trees, clock=clock)
