"""The tree runner: a behaviour tree (or a mode file's machine) ticking on the bus.

* :mod:`~cyborg.runner.tree_runner` — :class:`~cyborg.runner.tree_runner.TreeRunnerNode`:
  loads the file, ticks it, publishes its structure, path and status, and serves ``enable``,
  ``stop`` and ``reload``;
* :mod:`~cyborg.runner.tree_control` — per-node hooks, breakpoints, step and resume, and the
  blackboard (through :mod:`~cyborg.runner.blackboard_view`, bounded and strict JSON);
* :mod:`~cyborg.runner.background_reload` — loading the next file on a thread of its own;
* :mod:`~cyborg.runner.service_states`, :mod:`~cyborg.runner.status_message`,
  :mod:`~cyborg.runner.mode_endpoints` — what it publishes of services, ticks and modes;
* :mod:`~cyborg.runner.component` — the runner as a launch component, with its robot.

``cyborg bt serve`` and ``cyborg up`` (:mod:`cyborg.app`) start it; the contract it serves is
:mod:`cyborg.interfaces.tree_runner`. The package exports nothing itself: import the modules.
"""

__all__: list[str] = []
