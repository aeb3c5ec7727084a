"""The ``cyborg`` commands: each one's one-line help and the module that adds it, written once.

The command line imports a command's module only when that command runs: ``cyborg --help``
lists every command from this table alone, and ``cyborg bt validate FILE`` imports what
``cyborg bt`` needs, not the simulator, the detector or the Foxglove server. A module adds its
commands with the help written here (``COMMANDS[name].help``); ``tests/app/test_cli_startup.py``
checks that every command is in the table, once, with the module that adds it.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["COMMANDS", "Command", "command_in"]


@dataclass(frozen=True)
class Command:
    """A top-level command: the module of :mod:`cyborg.app` that adds it, and its help line."""

    module: str
    help: str


COMMANDS: dict[str, Command] = {
    "up": Command("up", "run the robot's system on built-in defaults"),
    "launch": Command("up", "start the nodes a launch file lists"),
    "monitor": Command("monitor_commands", "serve the web monitor for running behaviour trees"),
    "foxglove": Command("foxglove_commands", "serve the bus to the Foxglove app (WebSocket)"),
    "bt": Command("bt_commands", "behaviour trees: validate, run, export, serve, control"),
    "router": Command("bus_commands", "run a Zenoh router for the bus"),
    "node": Command("bus_commands", "nodes on the bus"),
    "topic": Command("bus_commands", "topics on the bus"),
    "service": Command("bus_commands", "services on the bus"),
    "record": Command("record_commands", "record the bus into an MCAP file (or --recover a cut "
                                         "one)"),
    "play": Command("play_commands", "play a recording (MCAP, ROS 1 or ROS 2 bag) on the bus"),
    "report": Command("report_commands", "write an HTML report of a recorded run"),
    "param": Command("param_commands", "parameters of a node"),
    "sim": Command("sim_commands", "run the simulated robot on an ARNL map"),
    "nav": Command("sim_commands", "goals and paths of an ARNL map"),
    "detect": Command("detect_commands", "detect objects (with distance) in images, videos, "
                                         "bags or the bus"),
}
"""Every top-level command, in the order ``cyborg --help`` lists them."""


def command_in(argv: list[str]) -> str | None:
    """The command ``argv`` names (its first word that is not an option), if it is one."""
    for word in argv:
        if not word.startswith("-"):
            return word if word in COMMANDS else None
    return None
