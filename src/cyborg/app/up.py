"""``cyborg up``: start the robot's main job on built-in defaults.

Today this runs the bundled demo mission (``data/demo.b3.json``, a behavior3editor project made
of stock nodes and nested subtrees) in the tree runner with a live status line. As the
simulator, navigation, monitor and detector arrive, ``cyborg up`` starts them too, so the same
command keeps bringing up the whole system.
"""

from __future__ import annotations

import argparse
import sys
from importlib.resources import as_file, files
from pathlib import Path
from typing import Any

from cyborg.app.bt_commands import (
    add_run_options,
    print_problems,
    run_clock,
    run_options_problem,
    run_tree,
)
from cyborg.bt import TreeLoadError, default_registry, load_tree

DEMO_TREE = "demo.b3.json"


def add_parser(commands: Any) -> None:
    up = commands.add_parser("up", help="run the main job on built-in defaults",
                             description="Start the robot's main job. With no options: the "
                                         "bundled demo mission in the tree runner.")
    up.add_argument("--tree", type=Path, default=None, metavar="FILE",
                    help="behavior3editor export to run instead of the bundled demo")
    add_run_options(up)
    up.set_defaults(handler=up_command)


def up_command(args: argparse.Namespace) -> int:
    problem = run_options_problem(args)
    if problem is not None:
        print(problem, file=sys.stderr)
        return 2
    clock = run_clock(args)
    resource = files("cyborg.app").joinpath("data", DEMO_TREE)
    with as_file(resource) as demo:
        path = args.tree or demo
        try:
            tree = load_tree(path, registry=default_registry(), clock=clock)
        except TreeLoadError as exc:
            print_problems(exc.problems, sys.stderr)
            return 1
        print("cyborg up:")
        print(f"  tree runner  {tree.title!r} ({len(tree)} nodes) from "
              f"{'the bundled demo' if args.tree is None else path}")
        return run_tree(tree, rate_hz=args.rate, max_ticks=args.ticks)
