"""The editor's stock actions: Succeeder, Failer, Runner, Error and Wait."""

from __future__ import annotations

from typing_extensions import override

from cyborg.bt.node import Action
from cyborg.bt.status import ERROR, FAILURE, RUNNING, SUCCESS, Status


class Succeeder(Action):
    """Always SUCCESS."""

    @override
    def tick(self) -> Status:
        return SUCCESS


class Failer(Action):
    """Always FAILURE."""

    @override
    def tick(self) -> Status:
        return FAILURE


class Runner(Action):
    """Always RUNNING."""

    @override
    def tick(self) -> Status:
        return RUNNING


class Error(Action):
    """Always ERROR."""

    @override
    def tick(self) -> Status:
        return ERROR


class Wait(Action):
    """RUNNING until ``milliseconds`` have passed since the activation began, then SUCCESS.

    ``Wait 0`` succeeds in its first tick. Time comes from the tree's clock.
    """

    def __init__(self, milliseconds: float = 0) -> None:
        self.milliseconds = milliseconds

    def check(self) -> list[str]:
        """The action's problems, plus a negative ``milliseconds``."""
        problems = super().check()
        if self.milliseconds < 0:
            problems.append(f"milliseconds must be 0 or more, not {self.milliseconds}")
        return problems

    def on_start(self) -> None:
        """Notes the activation's start (:attr:`now`) in ``memory["start"]``."""
        self.memory["start"] = self.now

    @override
    def tick(self) -> Status:
        if self.ms_since() >= self.milliseconds:
            return SUCCESS
        return RUNNING
