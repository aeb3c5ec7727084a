"""Launch descriptions: which nodes to start, with what parameters, in which processes.

A launch file is TOML (or YAML with the same keys)::

    [bus]
    listen = "tcp/127.0.0.1:7447"      # be the router here (default), or
    # connect = ["tcp/10.0.0.5:7447"]  # join a router elsewhere

    [[node]]
    kind = "simulator"                 # see cyborg.app.launchables for kinds and parameters
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
``cyborg launch FILE --process NAME`` that joins this one's bus. Ctrl-C (or SIGTERM) stops
every node and every child cleanly. Relative paths are relative to the launch file.
"""

from __future__ import annotations

import faulthandler
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

from cyborg.app.launchables import LaunchError, NodeSpec, Running, starter_for
from cyborg.bus import Context

NODE_KEYS = {"kind", "name", "namespace", "process", "parameters"}
DEFAULT_LISTEN = "tcp/127.0.0.1:7447"


@dataclass
class LaunchDescription:
    nodes: list[NodeSpec]
    connect: list[str] = field(default_factory=list)
    listen: str = DEFAULT_LISTEN
    source: str = "<built in>"

    def processes(self) -> list[str]:
        """Process names in order of first appearance, ``main`` first."""
        names = ["main"] + [spec.process for spec in self.nodes]
        return list(dict.fromkeys(names))


def read_launch(path: Path) -> LaunchDescription:
    """Parse and check a launch file; :class:`LaunchError` names the file, node and field."""
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise LaunchError(f"{path}: cannot read the launch file: {exc.strerror}") from exc
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
    return LaunchDescription(nodes, list(connect), str(bus.get("listen", DEFAULT_LISTEN)),
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
        """Start this process's nodes (stopping what started if one fails), then children."""
        try:
            for spec in self.description.nodes:
                if spec.process == process:
                    self.running.append(starter_for(spec)(self.context, spec))
        except BaseException:
            self.stop()
            raise
        for name in children or []:
            command = [sys.executable, "-m", "cyborg", "launch", self.description.source,
                       "--process", name, "--connect", connect]
            self.children.append((name, subprocess.Popen(command)))

    def describe(self) -> list[str]:
        lines = [item.describe() for item in self.running]
        lines += [f"process      {name} (pid {child.pid}): cyborg launch --process {name}"
                  for name, child in self.children]
        return lines

    def wait(self, duration: float | None = None) -> int:
        """Wait for Ctrl-C / SIGTERM (or ``duration`` seconds, or a child dying)."""
        previous = signal.signal(signal.SIGTERM, _interrupt)
        started = time.monotonic()
        try:
            while duration is None or time.monotonic() - started < duration:
                for name, child in self.children:
                    if child.poll() is not None:
                        print(f"cyborg launch: process {name} ended with code "
                              f"{child.returncode}", file=sys.stderr)
                        return 1
                time.sleep(0.2)
        except KeyboardInterrupt:
            return 130
        finally:
            signal.signal(signal.SIGTERM, previous)
        return 0

    def stop(self) -> None:
        """Stop children (SIGINT, then SIGKILL after 5 s) and this process's nodes;
        :attr:`stopping` says which part is stopping now."""
        self.stopping = "child processes"
        for _name, child in self.children:
            if child.poll() is None:
                child.send_signal(signal.SIGINT)
        for _name, child in self.children:
            try:
                child.wait(5.0)
            except subprocess.TimeoutExpired:
                child.kill()
        for item in reversed(self.running):
            self.stopping = item.describe()
            item.stop()
        self.stopping = "the bus and the interpreter's exit"
        self.running.clear()


STOP_DEADLINE = 20.0
"""Seconds a command's process may take to stop before it is ended with a report."""


def end_if_stuck(launch: Launch, deadline: float = STOP_DEADLINE) -> None:
    """For a command about to stop ``launch`` and exit: Ctrl-C always ends the process. If it
    is still alive ``deadline`` seconds from now, what was stopping and every thread's stack
    go to stderr and the process exits with code 1. (Not for a process that goes on.)"""
    def overdue() -> None:
        time.sleep(deadline)
        print(f"cyborg: still stopping after {deadline:g} s, at: {launch.stopping}; the "
              "threads' stacks follow, then the process ends", file=sys.stderr, flush=True)
        faulthandler.dump_traceback(file=sys.stderr)
        os._exit(1)
    threading.Thread(target=overdue, name="stop-deadline", daemon=True).start()


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt
