"""The kinds of component a launch file can start: each kind's start function, by name.

Each component's parameters, defaults and wiring live in its own package, in its component
module; this table only names them:

===============  ====================================================================
kind             start function (and its parameters)
===============  ====================================================================
``simulator``    :func:`cyborg.sim.component.start`
``tree_runner``  :func:`cyborg.runner.component.start`, with the robot on the bus
                 (:class:`~cyborg.robot.settling_robot.SettlingBusRobot`)
``monitor``      :func:`cyborg.monitor.component.start`
``foxglove``     :func:`cyborg.foxglove.component.start`
``camera``       :func:`cyborg.vision.component.start_camera`
``detector``     :func:`cyborg.vision.component.start_detector`
``recorder``     :func:`cyborg.record.component.start`
``tracker``      :func:`cyborg.perception.component.start`
===============  ====================================================================

Any other kind is given as ``"package.module:function"``: a start function
``start(context, spec) -> Running`` (see :mod:`cyborg.bus.component`), a user's own included.
"""

from __future__ import annotations

import importlib
from functools import partial

from cyborg.bus.component import NodeSpec, Starter
from cyborg.foxglove import component as foxglove
from cyborg.monitor import component as monitor
from cyborg.perception import component as perception
from cyborg.record import component as recorder
from cyborg.robot.settling_robot import SettlingBusRobot
from cyborg.runner import component as runner
from cyborg.sim import component as sim
from cyborg.vision import component as vision

KINDS: dict[str, Starter] = {
    "simulator": sim.start,
    "tree_runner": partial(runner.start, robot=SettlingBusRobot),  # app wires the robot in
    "monitor": monitor.start,
    "foxglove": foxglove.start,
    "camera": vision.start_camera,
    "detector": vision.start_detector,
    "recorder": recorder.start,
    "tracker": perception.start,
}
"""The start function of each kind a launch file may name."""


def starter_for(spec: NodeSpec) -> Starter:
    """The start function of ``spec.kind``: a known kind or ``module:function``."""
    if spec.kind in KINDS:
        return KINDS[spec.kind]
    module_name, _, function = spec.kind.partition(":")
    if not function:
        raise spec.error(f"unknown kind {spec.kind!r}; known: {', '.join(sorted(KINDS))}, "
                         "or 'package.module:function'")
    try:
        module = importlib.import_module(module_name)
        starter: Starter = getattr(module, function)
    except (ImportError, AttributeError) as exc:
        raise spec.error(f"cannot load kind {spec.kind!r}: {type(exc).__name__}: {exc}") from exc
    return starter
