"""Launch descriptions: which nodes to start, with what parameters, in which processes.

A launch file is TOML (or YAML with the same keys)::

    [bus]
    listen = "tcp/127.0.0.1:7447"      # be the router here (default), or
    # connect = ["tcp/10.0.0.5:7447"]  # join a router elsewhere

    [[node]]
    kind = "simulator"                 # see cyborg.app.launchables for the kinds
    name = "arnl"
    namespace = "/cyborg"
    process = "robot"                  # nodes with the same process share one (default "main")
    parameters = { map = "maps/AMROffice.map", speed = 10 }

    [[node]]
    kind = "tree_runner"
    name = "tree_runner"
    namespace = "/cyborg/bt"
    parameters = { tree_file = "patrol.b3.json", use_sim_time = true }

``cyborg launch FILE`` checks the whole file first (every problem names the file and the
node), then starts the ``main`` process's nodes here and each other process as a child
``cyborg launch FILE --process NAME`` that joins this one's bus. Relative paths are relative to
the launch file.

Ctrl-C (or SIGTERM) stops every node and every child cleanly, in this order (see
:meth:`Launch.stop`): the tree runners first, so each halts its tree and a running MoveTo
cancels its goal while the robot's nodes are still there to hear it; then the process's other
nodes, last started first; then the child processes, last started first, each one gone before
the next is asked. A terminal's Ctrl-C reaches every process of the job at once, so children
ignore SIGINT and wait for their parent's SIGTERM; a child whose parent dies stops by itself.
With ``-v`` each step is logged (``stopping tree runner /cyborg/bt/tree_runner``), by children
too: they run with their parent's verbosity.
"""

from __future__ import annotations

import faulthandler
import logging
import os
import signal
import subprocess
import sys
import threading
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from cyborg.app.errors import interrupt
from cyborg.app.launchables import starter_for
from cyborg.bus import Context
from cyborg.bus.component import LaunchError, NodeSpec, Running
from cyborg.bus.config import DEFAULT_ROUTER
from cyborg.interfaces import robot
from cyborg.runner.component import RunningTree

log = logging.getLogger("cyborg.app")
"""The logger of the launch's steps (``-v`` shows them)."""

NODE_KEYS = {"kind", "name", "namespace", "process", "parameters"}
"""The fields a ``[[node]]`` entry may have."""


@dataclass
class LaunchDescription:
    """What to start: the components, in which processes, on which bus."""

    nodes: list[NodeSpec]
    """The components, in the order they start."""
    connect: list[str] = field(default_factory=list)
    """Routers to join; none: be the router at :attr:`listen`."""
    listen: str = DEFAULT_ROUTER
    """Where to be the bus's router (or join the one already there)."""
    source: str = "<built in>"
    """The launch file, which child processes read again."""

    def processes(self) -> list[str]:
        """Process names in order of first appearance, ``main`` first."""
        names = ["main"] + [spec.process for spec in self.nodes]
        return list(dict.fromkeys(names))


def under_robot(namespace: str, default: str) -> str:
    """A component's default namespace, moved from the default robot's to ``namespace``.

    ``default`` lies under the robot's default namespace (``/cyborg``); the same place under
    the robot ``namespace`` is returned: ``/cyborg/bt`` under ``/robot1`` is ``/robot1/bt``.
    """
    if default != robot.NAMESPACE and not default.startswith(robot.NAMESPACE + "/"):
        raise ValueError(f"{default} is not under the robot's namespace {robot.NAMESPACE}")
    base = "/" + namespace.strip("/")
    return (base.rstrip("/") + default.removeprefix(robot.NAMESPACE)) or "/"


def read_launch(path: Path) -> LaunchDescription:
    """The launch file at ``path``, checked; :class:`LaunchError` names the file, node and field."""
    try:
        text = path.read_text(encoding="utf-8-sig")  # a byte-order mark, as Notepad writes
    except OSError as exc:
        raise LaunchError(f"{path}: cannot read the launch file: {exc.strerror}") from exc
    except UnicodeDecodeError as exc:
        line = path.read_bytes()[:exc.start].count(b"\n") + 1
        raise LaunchError(f"{path}:{line}: not UTF-8 text (byte {exc.start}: "
                          f"{exc.object[exc.start:exc.start + 1]!r})") from exc
    try:
        if path.suffix.lower() in (".yaml", ".yml"):
            data = yaml.safe_load(text) or {}
        else:
            data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise LaunchError(f"{path}: not valid TOML: {exc}") from exc
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f":{mark.line + 1}" if mark is not None else ""
        raise LaunchError(f"{path}{where}: not valid YAML: {exc}") from exc
    return parse_launch(data, path)


def parse_launch(data: Any, path: Path) -> LaunchDescription:
    """Checks the parsed content of the launch file ``path`` and makes it a description."""
    if not isinstance(data, dict):
        raise LaunchError(f"{path}: expected a table with [[node]] entries")
    unknown = set(data) - {"bus", "node"}
    if unknown:
        raise LaunchError(f"{path}: unknown section(s) {', '.join(sorted(unknown))}; "
                          "expected [bus] and [[node]]")
    bus = data.get("bus", {})
    if not isinstance(bus, dict) or set(bus) - {"connect", "listen"}:
        raise LaunchError(f"{path}: [bus] takes `connect` (a list) and `listen`")
    connect = bus.get("connect", [])
    if isinstance(connect, str):
        connect = [connect]
    entries = data.get("node", [])
    if not isinstance(entries, list) or not entries:
        raise LaunchError(f"{path}: no [[node]] entries: nothing to launch")
    nodes: list[NodeSpec] = []
    seen: set[str] = set()
    for index, entry in enumerate(entries, 1):
        where = f"{path}: node {index}"
        if not isinstance(entry, dict):
            raise LaunchError(f"{where}: expected a table")
        extra = set(entry) - NODE_KEYS
        if extra:
            raise LaunchError(f"{where}: unknown field(s) {', '.join(sorted(extra))}; "
                              f"fields are {', '.join(sorted(NODE_KEYS))}")
        for key in ("kind", "name"):
            if not isinstance(entry.get(key), str) or not entry[key]:
                raise LaunchError(f"{where}: field `{key}` is missing or not a string")
        parameters = entry.get("parameters", {})
        if not isinstance(parameters, dict):
            raise LaunchError(f"{where} ({entry['name']}): field `parameters` must be a table")
        spec = NodeSpec(kind=entry["kind"], name=entry["name"],
                        namespace=str(entry.get("namespace", "/")), parameters=parameters,
                        process=str(entry.get("process", "main")), base=path.parent,
                        where=f"{where} ({entry['name']})")
        full_name = f"{spec.namespace.rstrip('/')}/{spec.name}"
        if full_name in seen:
            raise LaunchError(f"{spec.where}: another node is already called {full_name}")
        seen.add(full_name)
        starter_for(spec)  # unknown kinds fail now, before anything starts
        nodes.append(spec)
    return LaunchDescription(nodes, list(connect), str(bus.get("listen", DEFAULT_ROUTER)),
                             str(path))


class Launch:
    """The running nodes of one process, plus its child processes."""

    def __init__(self, description: LaunchDescription, context: Context) -> None:
        self.description, self.context = description, context
        self.running: list[Running] = []
        self.children: list[tuple[str, subprocess.Popen[bytes]]] = []
        self.stopping = ""

    def start(self, process: str = "main", *, children: list[str] | None = None,
              connect: str = "") -> None:
        """Starts this process's nodes (stopping what started if one fails), then children."""
        try:
            for spec in self.description.nodes:
                if spec.process == process:
                    try:
                        self.running.append(starter_for(spec)(self.context, spec))
                    except LaunchError:
                        raise
                    except ValueError as exc:  # a parameter out of its limits or of a wrong type
                        raise spec.error(str(exc)) from exc
        except BaseException:
            self.stop()
            raise
        for name in children or []:
            command = [sys.executable, "-m", "cyborg", *_verbosity(), "launch",
                       self.description.source, "--process", name, "--connect", connect]
            self.children.append((name, subprocess.Popen(command)))

    def describe(self) -> list[str]:
        """What runs: each component's lines, then each child process."""
        lines = [item.describe() for item in self.running]
        lines += [f"process      {name} (pid {child.pid}): cyborg launch --process {name}"
                  for name, child in self.children]
        return lines

    def wait(self, duration: float | None = None, *, parent: int | None = None) -> int:
        """Waits for Ctrl-C or SIGTERM, or ``duration`` seconds; returns the exit code.

        It ends too when a child dies, or, in a child, when its ``parent`` process has ended:
        a launch killed outright leaves no orphans.
        """
        previous = signal.signal(signal.SIGTERM, interrupt)
        started = time.monotonic()
        try:
            while duration is None or time.monotonic() - started < duration:
                for name, child in self.children:
                    if child.poll() is not None:
                        print(f"cyborg launch: process {name} ended with code "
                              f"{child.returncode}", file=sys.stderr)
                        return 1
                if parent is not None and os.getppid() != parent:
                    print(f"cyborg launch: the launch that started this process (pid {parent}) "
                          "has ended", file=sys.stderr)
                    return 1
                time.sleep(0.2)
        except KeyboardInterrupt:
            return 130
        finally:
            signal.signal(signal.SIGTERM, previous)
        return 0

    def stop(self) -> None:
        """Stops what this launch started, each part while the parts it needs are still there.

        1. Tree runners, last started first. Each halts its tree: a running MoveTo cancels its
           goal and the runner waits (up to 5 s) until the robot has confirmed, so the robot
           stops and no "cancel failed" is reported, wherever the robot's nodes run.
        2. This process's other nodes, last started first (the detector before its camera,
           the simulator before the monitor that watched it).
        3. Child processes, last started first: SIGTERM, then SIGKILL if one is still there
           after 5 s; each is gone before the next is asked, and stops its own nodes the same
           way.

        :attr:`stopping` says which part is stopping now (for :func:`end_if_stuck`); with
        ``-v`` each step is logged.
        """
        trees = [item for item in self.running if isinstance(item, RunningTree)]
        others = [item for item in self.running if not isinstance(item, RunningTree)]
        for item in [*reversed(trees), *reversed(others)]:
            self._step(" ".join(item.describe().split(":", 1)[0].split()))
            item.stop()
        self.running.clear()
        for name, child in reversed(self.children):
            self._step(f"process {name} (pid {child.pid})")
            if child.poll() is None:
                child.send_signal(signal.SIGTERM)
            try:
                child.wait(5.0)
            except subprocess.TimeoutExpired:
                child.kill()
                child.wait()
        self.stopping = "the bus and the interpreter's exit"

    def _step(self, part: str) -> None:
        self.stopping = part
        log.info("stopping %s", part)


STOP_DEADLINE = 20.0
"""Seconds a command's process may take to stop before it is ended with a report."""


def end_if_stuck(launch: Launch, deadline: float = STOP_DEADLINE) -> None:
    """Ends the process if stopping ``launch`` takes longer than ``deadline`` seconds.

    For a command about to stop ``launch`` and exit, so that Ctrl-C always ends the process:
    if it is still alive ``deadline`` seconds from now, what was stopping and every thread's
    stack go to stderr and the process exits with code 1. (Not for a process that goes on.)
    """
    def overdue() -> None:
        time.sleep(deadline)
        print(f"cyborg: still stopping after {deadline:g} s, at: {launch.stopping}; the "
              "threads' stacks follow, then the process ends", file=sys.stderr, flush=True)
        faulthandler.dump_traceback(file=sys.stderr)
        os._exit(1)
    threading.Thread(target=overdue, name="stop-deadline", daemon=True).start()



def as_child() -> None:
    """Sets the signals of a launch's child process.

    SIGTERM (its parent's stop) interrupts it; SIGINT is ignored, since a terminal's Ctrl-C
    reaches the whole job and the parent stops its children only once its own tree runners
    have halted.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, interrupt)


def _verbosity() -> list[str]:
    """``-v`` / ``-vv`` for a child process, after this process's log level."""
    level = logging.getLogger().getEffectiveLevel()
    return ["-vv"] if level <= logging.DEBUG else ["-v"] if level <= logging.INFO else []
