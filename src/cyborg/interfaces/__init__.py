"""Contracts: the names, types and values two programs on the bus must agree on, written once.

A **contract** is what a server and its clients share: the names of the topics, services and
actions under a namespace, the message type of each, whether a topic is latched, the default
namespace, and the constants that travel in the messages (hook codes, dock states, outcomes).
When the two sides spell these apart, a renamed topic or a new code breaks one side silently —
the client waits for a topic nobody publishes. Here each is written once and both sides import
it, so a rename is a one-line edit and tests/interfaces/test_contracts.py checks, on a live bus,
that every client endpoint finds its server.

* :mod:`~cyborg.interfaces.contract` — the descriptors :class:`Topic`, :class:`Service` and
  :class:`Action` (name, message class or service or action type, QoS; they create either
  side's endpoint on a node, typed by that class), and name resolution;
* :mod:`~cyborg.interfaces.robot` — the robot's ARNL-like interface (simulator ↔ BusRobot);
* :mod:`~cyborg.interfaces.tree_runner` — the tree runner's topics and services (runner ↔
  monitor, command line);
* :mod:`~cyborg.interfaces.detector` — the camera's and the detector's topics.
* :mod:`~cyborg.interfaces.player` — the player's state and its pause, seek and step services
  (`cyborg play` ↔ a timeline).
* :mod:`~cyborg.interfaces.modes` — a mode machine's state, transitions, events and its
  request/force/hold service (tree runner of a mode file ↔ ``cyborg bt mode``, monitors).
* :mod:`~cyborg.interfaces.help` — a robot's call for help (its tree's robot ↔ whoever
  comes: ``cyborg topic echo /cyborg/help``, monitors).
* :mod:`~cyborg.interfaces.perception` — tracked objects on the map, the ``say`` topic, the
  camera's model and mount and the tracker's defaults (tracker ↔ tree nodes, simulated camera).

**Adding to a contract.** Declare the endpoint in the module of the program that serves it,
e.g. ``BUMPERS = Topic("bumper_state", BumperState, latched=True)`` with ``BumperState``
imported from :mod:`cyborg.bus.msgs.cyborg_msgs.msg`, use the descriptor on both sides
(``BUMPERS.publisher(node)`` / ``BUMPERS.subscription(node, on_bumpers, namespace)``: a
``Publisher[BumperState]`` and a callback that mypy checks), add it to the module's ``TOPICS``
or ``SERVICES`` tuple, and extend the test that starts both sides. A constant the message
carries belongs in the message definition (``uint8 FORCE=2`` in the .srv; constants do not
change the type hash or the wire format): declare it there, regenerate :mod:`cyborg.bus.msgs`
(``python3 -m cyborg.bus.codegen``) and take it from the class (``ControlNode_Request.FORCE``),
never retype it. Only values no message defines (ARNL's path states sent as a string) are
written here.

This package imports only itself and :mod:`cyborg.bus`; every layer above may import it.
"""

from cyborg.interfaces.contract import Action, Service, Topic, resolve

__all__ = ["Action", "Service", "Topic", "resolve"]
