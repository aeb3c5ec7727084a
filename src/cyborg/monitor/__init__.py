"""The web monitor for running behaviour trees, the successor of rqt_bt.

``cyborg monitor`` (or ``cyborg up``) serves a page that draws the tree a tree runner ticks,
live, and lets the person at the robot control it: run/pause, disable a subtree, force a result,
breakpoints and stepping, with the blackboard, per-node timings and a history timeline beside
it. See docs/monitor.md.

* :mod:`~cyborg.monitor.tree_state` — one tree's structure, statuses, timings, history (no I/O);
* :mod:`~cyborg.monitor.source` — one tree runner followed over the bus;
* :mod:`~cyborg.monitor.access` — who may reach the monitor (Host allow-list, origins, the
  token); :mod:`~cyborg.monitor.seat` — who may control, and who does;
* :mod:`~cyborg.monitor.limits` — what one viewer may cost (trees, connections, messages);
* :mod:`~cyborg.monitor.hub`, :mod:`~cyborg.monitor.client`, :mod:`~cyborg.monitor.commands` —
  browsers, their queues and their commands;
* :mod:`~cyborg.monitor.export` — DOT, SVG and PNG through Graphviz;
* :mod:`~cyborg.monitor.server` — the Starlette application; :mod:`~cyborg.monitor.monitor` —
  the node that runs it all.

This package uses the bus, the engine's DOT writer and its statuses; only :mod:`cyborg.app`
wires it up.
"""

from cyborg.monitor.access import TokenError, read_token
from cyborg.monitor.monitor import DEFAULT_HOST, DEFAULT_PORT, Monitor, MonitorError

__all__ = ["DEFAULT_HOST", "DEFAULT_PORT", "Monitor", "MonitorError", "TokenError", "read_token"]
