"""The simulated Pioneer LX on an ARNL map, and its bus node.

* :mod:`~cyborg.sim.simulator` steps the world in simulated time: the base
  (:mod:`~cyborg.sim.robot`), :mod:`~cyborg.sim.laser`, :mod:`~cyborg.sim.battery`,
  :mod:`~cyborg.sim.docking` and :mod:`~cyborg.sim.navigator` (which follows paths with
  :mod:`~cyborg.sim.follower` and checks commands with :mod:`~cyborg.sim.motion_check`), from
  the pose :mod:`~cyborg.sim.start` chooses;
* :mod:`~cyborg.sim.loop` runs it against the wall clock on a thread of its own;
* :mod:`~cyborg.sim.node` puts it on the bus with an ARNL-like interface.

The package exports nothing itself: import the modules.
"""

__all__: list[str] = []
