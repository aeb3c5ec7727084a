"""What starting a component takes and gives: a :class:`NodeSpec` in, a :class:`Running` out.

A *component* is a set of bus nodes that start and stop together: the simulator, a tree
runner, the web monitor, a camera, a detector. Each lives in its own package, with a module
holding its parameters, their defaults and its wiring, and one function::

    def start(context: Context, spec: NodeSpec) -> Running

which creates its node(s) in ``context`` under the spec's name and namespace, declares its bus
parameters with their defaults (``spec.parameters`` set them, so ``cyborg param list`` shows
them), starts working and returns a handle that says what runs (:meth:`Running.describe`) and
stops it (:meth:`Running.stop`). A spec it cannot start from is refused with
:meth:`NodeSpec.error`, which names where the spec was written. Launch files, ``cyborg up``
and the other commands (:mod:`cyborg.app`) only build specs and pick the start function.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

from cyborg.bus.context import Context


class LaunchError(ValueError):
    """A component that cannot start as specified; the message says where and why."""


@dataclass
class NodeSpec:
    """What a component is started from: one entry of a launch description."""

    kind: str
    """Which component: a kind of the launch table, or ``package.module:function``."""
    name: str
    """The name of its (main) node."""
    namespace: str = "/"
    """The namespace of its node(s)."""
    parameters: dict[str, Any] = field(default_factory=dict)
    """Values of its bus parameters; the ones not given keep the component's defaults."""
    process: str = "main"
    """The launch's process that runs it (nodes with the same one share a process)."""
    base: Path = Path(".")
    """Folder that relative paths in parameters are relative to (the launch file's)."""
    where: str = ""
    """Where the entry was written (``file: node 2``), for error messages."""

    def path(self, value: str) -> Path:
        """The path a parameter names: ``~`` expanded, a relative one taken from :attr:`base`."""
        path = Path(value).expanduser()
        return path if path.is_absolute() else self.base / path

    def error(self, message: str) -> LaunchError:
        """The error that refuses this spec, prefixed with where it was written."""
        return LaunchError(f"{self.where or self.name}: {message}")


class Running(Protocol):
    """A started component: the handle its start function returns."""

    def describe(self) -> str:
        """One line (or a few) saying what runs and where, for the terminal."""
        ...

    def stop(self) -> None:
        """Stops working and leaves the bus."""
        ...


Starter = Callable[[Context, NodeSpec], Running]
"""A component's start function: ``start(context, spec) -> Running``."""
