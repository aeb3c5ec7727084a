"""What a launch file's entry becomes: a :class:`NodeSpec`, started into a :class:`Running`."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

from cyborg.bus import Context


class LaunchError(ValueError):
    """A launch description that cannot be started; the message says where and why."""


@dataclass
class NodeSpec:
    """One entry of a launch description."""

    kind: str
    name: str
    namespace: str = "/"
    parameters: dict[str, Any] = field(default_factory=dict)
    process: str = "main"
    base: Path = Path(".")
    """Folder that relative paths in parameters are relative to (the launch file's)."""
    where: str = ""
    """Where the entry was written (``file: node 2``), for error messages."""

    def path(self, value: str) -> Path:
        path = Path(value).expanduser()
        return path if path.is_absolute() else self.base / path

    def error(self, message: str) -> LaunchError:
        return LaunchError(f"{self.where or self.name}: {message}")


class Running(Protocol):
    def describe(self) -> str: ...
    def stop(self) -> None: ...


Starter = Callable[[Context, NodeSpec], Running]
