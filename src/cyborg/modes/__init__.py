"""Modes: one behaviour tree per mode, and a machine that chooses which tree runs.

A mode file (TOML, next to the editor project) declares the modes, the tree each runs, the
initial mode and the transitions between them — on conditions over the global blackboard
(``battery.percent < 20``), on events, on requests — with guards, a minimum dwell time and
time limits::

    from cyborg.modes import load_machine

    machine = load_machine("mission.modes.toml", clock=clock, blackboard=blackboard)
    snapshot = machine.tick()        # ticks the current mode's tree, then its transitions
    machine.request("demo", "visitor pressed the button")
    machine.force("normal")          # the operator's override
    machine.hold(True)               # the operator keeps the current mode

Errors in the file raise :class:`ModeFileError` naming the file, line and the mode or
transition. The package builds on :mod:`cyborg.bt` only; docs/modes.md describes it all.
"""

from cyborg.modes.conditions import Condition
from cyborg.modes.loading import build_machine, load_machine
from cyborg.modes.machine import ModeMachine
from cyborg.modes.mode_file import ModeFileError, parse_mode_file, read_mode_file
from cyborg.modes.records import Decision, ModeTick, Transition, Trigger
from cyborg.modes.spec import ANY, SCHEMA, MachineSpec, ModeSpec, TransitionSpec

__all__ = [
    "ANY",
    "SCHEMA",
    "Condition",
    "Decision",
    "MachineSpec",
    "ModeFileError",
    "ModeMachine",
    "ModeSpec",
    "ModeTick",
    "Transition",
    "TransitionSpec",
    "Trigger",
    "build_machine",
    "load_machine",
    "parse_mode_file",
    "read_mode_file",
]
