"""``cyborg bt mode``: request, force, hold and release a mode of a running mode machine."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from cyborg.app.cli import main
from cyborg.bt import ManualClock
from cyborg.bus import BusConfig, Context, Node
from cyborg.modes import ModeMachine
from cyborg.runner.tree_runner import TreeRunnerNode
from tests.builders import registry
from tests.modes.machines import write_modes, write_project
from tests.modes.test_machine import MISSION, TREES
from tests.ports import free_port


@pytest.fixture
def served(tmp_path: Path) -> Iterator[tuple[str, ModeMachine]]:
    """A router in this process with a runner of the test mission under /cyborg/bt."""
    address = f"tcp/127.0.0.1:{free_port()}"
    context = Context(BusConfig.router([address]))
    write_project(tmp_path, TREES)
    runner = TreeRunnerNode(Node("tree_runner", "/cyborg/bt", context=context),
                            write_modes(tmp_path, MISSION), registry=registry(),
                            clock=ManualClock(), enabled=False)
    runner.start()
    assert isinstance(runner.ticked, ModeMachine)
    try:
        yield address, runner.ticked
    finally:
        runner.destroy()
        context.close()


def test_the_mode_command_requests_forces_holds_and_releases(
        served: tuple[str, ModeMachine], capsys: pytest.CaptureFixture[str]) -> None:
    address, machine = served
    bus = ["--connect", address, "--wait", "0.3"]
    assert main(["bt", "mode", "demo", "--reason", "visitors", *bus]) == 0
    assert machine.mode == "demo" and machine.history[-1].reason == "visitors"
    assert "entered mode 'demo' (mode now: demo)" in capsys.readouterr().out
    assert main(["bt", "mode", "--hold", *bus]) == 0 and machine.held
    assert main(["bt", "mode", "normal", "--force", *bus]) == 0
    assert machine.mode == "normal" and machine.held
    assert main(["bt", "mode", "demo", *bus]) == 1  # held: a request is refused
    assert "held by the operator" in capsys.readouterr().out
    assert main(["bt", "mode", "--release", *bus]) == 0 and not machine.held
    assert main(["bt", "mode", "demo", *bus]) == 0 and machine.mode == "demo"


def test_the_mode_command_refuses_what_makes_no_sense(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bt", "mode"]) == 1
    assert "name the mode to enter" in capsys.readouterr().err
    assert main(["bt", "mode", "demo", "--hold"]) == 1
    assert "--hold applies to the current mode" in capsys.readouterr().err
