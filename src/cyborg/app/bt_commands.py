"""``cyborg bt ...``: validate, run and export behavior3editor trees from the shell."""

from __future__ import annotations

import argparse
import json
import signal
import sys
from pathlib import Path
from typing import Any, TextIO

from cyborg.app.command_table import COMMANDS
from cyborg.app.errors import CommandError, interrupt
from cyborg.app.status_line import StatusLine
from cyborg.app.terminal import errors_on_one_line
from cyborg.bt import (
    Clock,
    ManualClock,
    MonotonicClock,
    NodeRegistry,
    Status,
    TickLoop,
    Tree,
    TreeLoadError,
    check_file,
    default_registry,
    load_tree,
)
from cyborg.bt.problems import Problem, Severity
from cyborg.bt.registry import NodeModuleError
from cyborg.bt.tick_loop import DEFAULT_RATE
from cyborg.robot.protocol import ROBOT


def add_parser(commands: Any) -> Any:
    """Adds ``cyborg bt`` and its offline subcommands; returns their group.

    :mod:`cyborg.app.cli` adds the tree runner's subcommands to the group
    (:mod:`cyborg.app.runner_commands`).
    """
    bt = commands.add_parser("bt", help=COMMANDS["bt"].help,
                             description="Work with behavior3editor exports.")
    sub = bt.add_subparsers(dest="bt_command", metavar="SUBCOMMAND", required=True)

    validate = sub.add_parser("validate", help="report every problem in a tree file")
    _file_options(validate)
    validate.add_argument("--json", action="store_true", help="problems as JSON on stdout")
    validate.set_defaults(handler=validate_command)

    run = sub.add_parser("run", help="tick a tree with a live status line")
    _file_options(run)
    add_run_options(run)
    run.add_argument("--until-done", action="store_true",
                     help="stop when the root returns SUCCESS, FAILURE or ERROR")
    run.set_defaults(handler=run_command)

    dot = sub.add_parser("dot", help="print the tree as a Graphviz DOT graph")
    _file_options(dot)
    dot.add_argument("-o", "--output", type=Path, help="write to this file instead of stdout")
    dot.set_defaults(handler=dot_command)

    structure = sub.add_parser("json", help="print the tree's structure as JSON")
    _file_options(structure)
    structure.add_argument("-o", "--output", type=Path, help="write to this file")
    structure.set_defaults(handler=json_command)

    nodes = sub.add_parser("nodes", help="list the node types trees can use")
    nodes.add_argument("--nodes", action="append", default=[], metavar="MODULE",
                       help="also import this module of node classes (repeatable)")
    nodes.set_defaults(handler=nodes_command)
    return sub


def _file_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", type=Path, help="behavior3editor export (project, tree, "
                        "node list or desktop project file)")
    parser.add_argument("--tree", metavar="ID|TITLE",
                        help="the tree to use (default: the file's selectedTree)")
    parser.add_argument("--nodes", action="append", default=[], metavar="MODULE",
                        help="import this module of node classes first (repeatable)")
    parser.add_argument("--stub-missing", type=Status.parse, metavar="STATUS",
                        help="stand a stub returning STATUS (success, failure, running) in for "
                             "every node without a Python class")


def add_run_options(parser: argparse.ArgumentParser) -> None:
    """``--rate``, ``--ticks`` and ``--fast``, shared by every command that runs a tree."""
    parser.add_argument("--rate", type=float, default=DEFAULT_RATE, metavar="HZ",
                        help=f"tree ticks per second (default {DEFAULT_RATE:g})")
    parser.add_argument("--ticks", type=int, default=None, metavar="N",
                        help="stop after N ticks (default: run until Ctrl-C)")
    parser.add_argument("--fast", action="store_true",
                        help="simulated time: tick as fast as possible while nodes see the rate")


def run_options_problem(args: argparse.Namespace) -> str | None:
    """What is wrong with ``--rate``/``--ticks``, if anything."""
    if not args.rate > 0:
        return f"--rate must be more than 0, not {args.rate}"
    if args.ticks is not None and args.ticks < 1:
        return f"--ticks must be at least 1, not {args.ticks}"
    return None


def run_clock(args: argparse.Namespace) -> Clock:
    """Simulated time with ``--fast``, else the wall clock."""
    return ManualClock() if args.fast else MonotonicClock()


def registry_for(args: argparse.Namespace) -> NodeRegistry:
    """The node types trees may use: the installed ones and those of ``--nodes``."""
    registry = default_registry()
    try:
        registry.import_modules(args.nodes)
    except NodeModuleError as exc:
        raise CommandError(f"{exc} (--nodes)") from exc
    return registry


def print_problems(problems: list[Problem], stream: TextIO) -> None:
    """Prints ``problems`` to ``stream``, one a line, by file and line."""
    for problem in sorted(problems, key=lambda p: (p.source, p.line or 0)):
        print(problem, file=stream)


def _load(args: argparse.Namespace, **options: Any) -> Tree | None:
    try:
        return load_tree(args.file, tree=args.tree, registry=registry_for(args),
                         stub_missing=args.stub_missing, **options)
    except TreeLoadError as exc:
        print_problems(exc.problems, sys.stderr)
        errors = sum(p.is_error for p in exc.problems)
        print(f"{args.file}: {errors} error{'s' if errors != 1 else ''}; not loaded",
              file=sys.stderr)
        return None


def validate_command(args: argparse.Namespace) -> int:
    """``cyborg bt validate``: every problem of a tree file; 1 if one is an error."""
    problems = check_file(args.file, tree=args.tree, registry=registry_for(args),
                          stub_missing=args.stub_missing)
    errors = sum(p.is_error for p in problems)
    notes = sum(p.severity is Severity.NOTE for p in problems)
    warnings = len(problems) - errors - notes
    if args.json:
        json.dump([_problem_json(p) for p in problems], sys.stdout, indent=2)
        print()
    else:
        print_problems(problems, sys.stdout)
        verdict = "invalid" if errors else "ok"
        noted = f", {notes} note{'s' if notes != 1 else ''}" if notes else ""
        print(f"{args.file}: {verdict} ({errors} error{'s' if errors != 1 else ''}, "
              f"{warnings} warning{'s' if warnings != 1 else ''}{noted})")
    return 1 if errors else 0


def _problem_json(problem: Problem) -> dict[str, Any]:
    return {"severity": problem.severity.value, "message": problem.message,
            "file": problem.source, "line": problem.line, "column": problem.column,
            "tree": problem.tree, "node_id": problem.node_id, "node_title": problem.node_title,
            "field": problem.field}


def run_command(args: argparse.Namespace) -> int:
    """``cyborg bt run``: ticks a tree file in the foreground with a live status line."""
    problem = run_options_problem(args)
    if problem is not None:
        print(problem, file=sys.stderr)
        return 2
    tree = _load(args, clock=run_clock(args))
    if tree is None:
        return 1
    lacking = missing_resources_line(tree, str(args.file))
    if lacking:
        print(lacking, file=sys.stderr)
        return 2
    return run_tree(tree, rate_hz=args.rate, max_ticks=args.ticks, until_done=args.until_done)


_HOW_TO_GIVE = {
    ROBOT: "run it on the simulated robot with `cyborg up --tree FILE` (or `cyborg bt serve "
           "FILE` beside `cyborg sim`), or stand stubs in with --stub-missing running",
}


def missing_resources_line(tree: Tree, source: str) -> str:
    """One line naming the nodes that need a resource the tree lacks, and how to give it.

    Empty when nothing is missing.
    """
    parts = []
    for key, nodes in tree.missing_resources().items():
        names = sorted({node.name for node in nodes})
        how = _HOW_TO_GIVE.get(key, f"give the tree a {key!r} resource, or stand stubs in "
                                    "with --stub-missing running")
        parts.append(f"{len(nodes)} node{'s' if len(nodes) != 1 else ''} "
                     f"({', '.join(names)}) need a {key} and `cyborg bt run` has none: {how}")
    return f"{source}: " + "; ".join(parts) if parts else ""


def run_tree(tree: Tree, *, rate_hz: float, max_ticks: int | None = None,
             until_done: bool = False, stream: TextIO | None = None) -> int:
    """Ticks ``tree`` in the foreground with a status line until done or Ctrl-C.

    The exit status: 130 after Ctrl-C, 1 when the root's last status is ERROR or a tick
    overran its limit (the tree is halted), else 0. A node that raises is reported in one line
    (its id, label, the error and where it was raised), and log records and the nodes' prints
    are written above the live line.
    """
    stream = stream or sys.stdout
    runner = TickLoop(tree, rate_hz=rate_hz)
    line = StatusLine(tree, stream)
    runner.add_listener(line.update)
    overran: list[str] = []

    def end_after_overrun(reason: str) -> None:
        overran.append(reason)
        runner.stop()
    runner.add_interrupt_listener(end_after_overrun)
    print(f"running {tree.title!r} from {tree.source} ({len(tree)} nodes) at {rate_hz:g} Hz; "
          "Ctrl-C stops", file=stream)
    previous = signal.signal(signal.SIGTERM, interrupt)
    interrupted = False
    line.attach()
    try:
        with errors_on_one_line():  # a node's error: one line naming it, never a traceback
            runner.run(max_ticks=max_ticks, until_done=until_done)
    except KeyboardInterrupt:
        interrupted = True
        runner.stop()
    finally:
        signal.signal(signal.SIGTERM, previous)
        line.finish(interrupted=interrupted)
    if interrupted:
        return 130
    if overran:
        return 1  # the loop has logged why, naming the node
    return 1 if tree.last is not None and tree.last.status is Status.ERROR else 0



def _write(text: str, output: Path | None) -> None:
    if output is None:
        sys.stdout.write(text)
    else:
        output.write_text(text, encoding="utf-8")


def dot_command(args: argparse.Namespace) -> int:
    """``cyborg bt dot``: the tree as a Graphviz DOT graph."""
    tree = _load(args)
    if tree is None:
        return 1
    _write(tree.to_dot(), args.output)
    return 0


def json_command(args: argparse.Namespace) -> int:
    """``cyborg bt json``: the tree's structure as JSON."""
    tree = _load(args)
    if tree is None:
        return 1
    _write(json.dumps(tree.structure.to_json(), indent=2) + "\n", args.output)
    return 0


def nodes_command(args: argparse.Namespace) -> int:
    """``cyborg bt nodes``: the node types trees can use, with their properties."""
    registry = registry_for(args)
    for node_type in registry.types():
        params = ", ".join(
            param.editor_name + ("" if param.required else f"={param.default!r}")
            for param in node_type.signature.params)
        print(f"{node_type.name:<20} {node_type.category.value:<10} "
              f"{{{params}}}  [{node_type.origin}]")
    return 0
