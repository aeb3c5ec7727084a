"""The bus served to the Foxglove app, live, over the Foxglove WebSocket protocol (foxglove-sdk).

* :mod:`~cyborg.foxglove.server` — :class:`FoxgloveServer`: the SDK's server behind the gate;
* :mod:`~cyborg.foxglove.admission`, :mod:`~cyborg.foxglove.gate` — who may connect (the
  monitor's rules: loopback by default, a token for other machines) and the gate that checks;
  :mod:`~cyborg.foxglove.resubscribe` — the gate's frame-by-frame copy of a connection, which
  sends again a subscription the SDK refused for a channel it had only just advertised;
* :mod:`~cyborg.foxglove.bridge`, :mod:`~cyborg.foxglove.catalogue` — which channels the bus
  calls for, kept in step with it;
* :mod:`~cyborg.foxglove.relay`, :mod:`~cyborg.foxglove.topic_relay`,
  :mod:`~cyborg.foxglove.derived_relay` — channels fed from the bus only while watched; ROS 2
  topics pass through as their CDR bytes with their ``ros2msg`` schemas
  (:mod:`~cyborg.foxglove.schemas`);
* :mod:`~cyborg.foxglove.robot_relays` — each robot's map as an occupancy grid
  (:mod:`~cyborg.foxglove.map_grid`) and a scene (:mod:`~cyborg.foxglove.map_scene`), and its
  frame; :mod:`~cyborg.foxglove.tree_relay` — each tree's ticks as JSON;
* :mod:`~cyborg.foxglove.component` — the ``foxglove`` component of launch files.

It uses the bus, the contracts, navigation's grid and the engine's status names; only
:mod:`cyborg.app` imports it. See docs/foxglove.md.
"""

from cyborg.foxglove.server import DEFAULT_HOST, DEFAULT_PORT, FoxgloveError, FoxgloveServer

__all__ = ["DEFAULT_HOST", "DEFAULT_PORT", "FoxgloveError", "FoxgloveServer"]
