"""The map's switchboard: robots on the bus on one side, pages that show the map on the other.

Owned by :class:`~cyborg.monitor.hub.Hub`; everything here runs on the web server's event loop
except :meth:`RobotHub.notify`, which the bus calls from its threads.

* **Robots** are found by their pose topic (:func:`cyborg.interfaces.robot.robot_namespace`)
  and followed by one :class:`~cyborg.monitor.robot_source.RobotSource` each, at most
  :data:`ROBOT_LIMIT` at once (a robot that left makes room for a new one). A robot is paired
  with the tree runner that drives it by the namespace convention
  (:func:`cyborg.interfaces.tree_runner.robot_of_runner`).
* **Pages opt in** with ``{"t": "map", "on": true}``; the rest of this goes only to them. A page
  that opts in gets, per robot, its ``map_ref``, its ``path``, an ``rs`` and its warnings.
* **Robot state** goes out as ``rs``, throttled per robot: :data:`RS_GATHER` after the first
  change when :data:`RS_INTERVAL` has passed since that robot's last one, else then; the short
  wait gathers a pose and the scan published right after it into one ``rs``. A 10 Hz robot passes
  unchanged, the simulator's 30 Hz becomes about 12 Hz. An ``rs`` carries the pose, and the
  scan (with the laser's mount) when a new one came; the path state, battery and the current
  path's id when known; the footprint, the current goal and the running node only when they
  changed (and in the first ``rs`` a page gets), as pages keep them.
* **The running node** of the tree that drives a robot (``/robot1/bt`` drives ``/robot1``) is
  the deepest node of its active path
  (:meth:`~cyborg.monitor.tree_state.TreeState.running_label`); :meth:`RobotHub.tree_changed`
  hears of each tree's frames and sends the label in ``rs`` as ``node`` when it changed.
* **Paths** go out as ``path`` when a new one comes, at most one per :data:`PATH_INTERVAL` per
  robot; **maps** are laid out and gzipped in a worker thread (:mod:`cyborg.monitor.map_store`)
  and announced as ``map_ref`` (``key`` null when the robot's map was refused).
* **Detections**: while some page shows the map, each robot's detector (``/robot1/detector``
  for ``/robot1``, :func:`cyborg.interfaces.detector.detector_of_robot`) is listened to, and
  what it saw goes out placed on the map as ``det``, at most one per
  :data:`DETECTIONS_INTERVAL` per robot (:mod:`cyborg.monitor.detection_wire`).
* **Tracked objects**: while some page shows the map, each robot's ``objects`` (its tracker's,
  :data:`cyborg.interfaces.perception.OBJECTS`) are listened to, and go out checked as ``obj``,
  at most one per :data:`OBJECTS_INTERVAL` per robot (:mod:`cyborg.monitor.object_wire`).
* **Warnings** about a robot's messages go out as ``robot_warn``, at most one per second per
  kind, with how often it happened.

Every text is encoded once per message (:func:`~cyborg.monitor.robot_wire.wire_text`) and
queued to every page that shows the map.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import time
from collections.abc import Callable, Collection, Mapping
from typing import Any

from cyborg.interfaces.tree_runner import robot_of_runner
from cyborg.monitor.client import Client
from cyborg.monitor.limits import check_namespace
from cyborg.monitor.map_store import MapStore
from cyborg.monitor.off_loop import ShutdownError, in_thread
from cyborg.monitor.robot_outbox import RobotOutbox, Throttle
from cyborg.monitor.robot_source import RobotSource
from cyborg.monitor.robot_wire import wire_text
from cyborg.monitor.source import TreeSource

log = logging.getLogger("cyborg.monitor")

ROBOT_LIMIT = 16
"""Most robots the monitor follows at once."""
RS_INTERVAL = 0.08
"""Shortest time between two ``rs`` messages of one robot (s)."""
RS_GATHER = 0.005
"""How long a robot's first change waits for the ones published with it (s): a pose and its
scan come back to back, and sent apart the scan's ``rs`` would hold the next pose back by up to
:data:`RS_INTERVAL`."""
PATH_INTERVAL = 0.5
"""Shortest time between two ``path`` messages of one robot (s)."""
DETECTIONS_INTERVAL = 0.2
"""Shortest time between two ``det`` messages of one robot (s): at most 5 a second."""
OBJECTS_INTERVAL = 0.2
"""Shortest time between two ``obj`` messages of one robot (s): at most 5 a second."""
OBJECTS_KEPT = 3.0
"""A page that starts to look is sent a robot's tracked objects only if they came within this
many seconds (the page itself stops drawing them as long after the last ``obj``)."""
RS_KINDS = frozenset({"pose", "scan", "state", "battery", "goal", "footprint"})
"""Changes that an ``rs`` message tells."""


class RobotHub:
    """Connects :class:`RobotSource` objects to the pages that show the map.

    ``clients`` and ``trees`` are the hub's own (its connected pages, the tree sources it
    follows by namespace), ``changed`` broadcasts the ``robots`` list; robots are made and found
    by the functions given to :meth:`use` (none until then).
    """

    def __init__(self, clients: Collection[Client], trees: Mapping[str, TreeSource],
                 changed: Callable[[], None], store: MapStore | None = None) -> None:
        self._clients, self._trees, self._changed = clients, trees, changed
        self.store = store or MapStore()
        self.robots: dict[str, RobotOutbox] = {}
        self._make: Callable[[str], RobotSource] | None = None
        self._discover: Callable[[], list[str]] = list
        self._loop: asyncio.AbstractEventLoop | None = None
        self._pending: set[str] = set()
        self._tasks: set[asyncio.Task[None]] = set()
        self._warned_limit = False

    def use(self, make_source: Callable[[str], RobotSource],
            discover: Callable[[], list[str]]) -> None:
        """Follows robots from now on, with these two functions.

        ``discover()`` lists the robots' namespaces on the bus, ``make_source(namespace)``
        follows one.
        """
        self._make, self._discover = make_source, discover

    def attach(self, loop: asyncio.AbstractEventLoop) -> None:
        """Binds the hub to the server's event loop; :meth:`notify` drops changes until then."""
        self._loop = loop

    async def detach(self) -> None:
        """Lets go of the event loop as the server stops.

        Changes are dropped from now on, :meth:`periodic` does nothing, and maps being laid out
        are given up, so no work is handed to the closing loop's threads. (Work refused because
        the process exits first ends quietly too: :mod:`cyborg.monitor.off_loop`.)
        """
        self._loop = None
        tasks = list(self._tasks)
        for task in tasks:
            task.cancel()
        await asyncio.gather(*tasks, return_exceptions=True)

    # ------------------------------------------------------------------ robots
    async def periodic(self) -> None:
        """Follows robots that appeared, and sends warnings that waited; from the hub's loop.

        Never raises: a failure is logged, and the hub's other periodic work goes on.
        """
        if self._loop is None:
            return  # detached: the server stops
        try:
            if self._make is not None:
                changed = False
                for namespace in await in_thread(self._discover):
                    changed = self._found(namespace) or changed
                if changed:
                    self._changed()
            self._follow_seen()  # robots found, pages gone
            for robot in list(self.robots.values()):
                if robot.source.warnings.pending():
                    self._send_warnings(robot, self._viewers())
        except ShutdownError:
            return
        except Exception:
            log.exception("monitor: could not look for robots")

    def _found(self, namespace: str) -> bool:
        if namespace in self.robots or self._make is None:
            return False
        try:
            namespace = check_namespace(namespace)
        except ValueError:
            return False  # a root or otherwise odd namespace: not one a page can name
        if len(self.robots) >= ROBOT_LIMIT:
            gone = next((name for name, robot in sorted(self.robots.items())
                         if not robot.source.alive), None)
            if gone is None:
                if not self._warned_limit:
                    log.warning("more than %d robots on the bus: the map shows the first",
                                ROBOT_LIMIT)
                    self._warned_limit = True
                return False
            self._release(gone)
        self.robots[namespace] = RobotOutbox(self._make(namespace), Throttle(PATH_INTERVAL),
                                             Throttle(DETECTIONS_INTERVAL),
                                             Throttle(OBJECTS_INTERVAL))
        self.tree_changed(self._tree_of(namespace) or "")  # what its tree runs now
        self._request(namespace)  # what arrived while the source was being made
        return True

    def _release(self, namespace: str) -> None:
        robot = self.robots.pop(namespace, None)
        self._pending.discard(namespace)
        if robot is not None:
            try:
                robot.source.destroy()
            except Exception:
                log.exception("could not stop following robot %s", namespace)

    def describe(self) -> list[dict[str, Any]]:
        """The robots for the ``robots`` message: namespace, paired tree, alive, map key."""
        return [{"ns": namespace, "tree": self._tree_of(namespace),
                 "alive": robot.source.alive, "map": robot.map.key if robot.map else None}
                for namespace, robot in sorted(self.robots.items())]

    def _tree_of(self, namespace: str) -> str | None:
        return next((tree for tree in sorted(self._trees)
                     if robot_of_runner(tree) == namespace), None)

    def tree_changed(self, tree: str) -> None:
        """The tree runner under ``tree`` ticked, restarted or left: its robot's running node.

        Its robot (``/x`` for ``/x/bt``) is sent the new label when it changed; the label is ""
        when the runner is gone or nothing runs.
        """
        robot = self.robots.get(robot_of_runner(tree) or "")
        if robot is None:
            return
        source = self._trees.get(tree)
        state = source.state if source is not None and source.alive else None
        label = state.running_label() if state is not None else ""
        if label != robot.node:
            robot.node = label
            self._request(robot.source.namespace)

    def destroy(self) -> None:
        """Stops following every robot."""
        for namespace in list(self.robots):
            self._release(namespace)

    # ------------------------------------------------------------------ from the bus
    def notify(self, namespace: str, _what: str) -> None:
        """Called from any thread when something changed for the robot under ``namespace``."""
        loop = self._loop
        if loop is None or loop.is_closed() or namespace in self._pending:
            return
        self._pending.add(namespace)
        with contextlib.suppress(RuntimeError):  # the loop closed meanwhile
            loop.call_soon_threadsafe(self._wake, namespace)

    def _request(self, namespace: str) -> None:
        """:meth:`notify` from the loop itself."""
        if namespace not in self._pending:
            self._pending.add(namespace)
            self._wake(namespace)

    def _wake(self, namespace: str) -> None:
        robot = self.robots.get(namespace)
        if robot is None or self._loop is None:
            self._pending.discard(namespace)
            return
        delay = max(robot.last + RS_INTERVAL - time.monotonic(), RS_GATHER)
        self._loop.call_later(delay, self._flush, namespace)

    def _flush(self, namespace: str) -> None:
        self._pending.discard(namespace)
        robot = self.robots.get(namespace)
        if robot is None:
            return
        try:
            self._send_changes(robot)
        except Exception:
            log.exception("monitor: could not send the state of robot %s", namespace)

    def _send_changes(self, robot: RobotOutbox) -> None:
        source = robot.source
        robot.last = time.monotonic()
        changes = source.take_changes()
        if "map" in changes:
            self._build(robot)
        if "alive" in changes:
            self._changed()
        viewers = self._viewers()
        if self._throttled(robot, robot.path_throttle, source.path_id, viewers,
                           robot.path_message):
            changes.add("path")
        if viewers and (changes & (RS_KINDS | {"path"}) or robot.unsent()):
            state = robot.rs_message(scan="scan" in changes)
            if state is not None:
                robot.sent_to_all()
            self._send(viewers, state)
        self._throttled(robot, robot.detections_throttle, source.detections_id, viewers,
                        robot.detections_message)
        self._throttled(robot, robot.objects_throttle, source.objects_id, viewers,
                        robot.objects_message)
        if "warn" in changes:
            self._send_warnings(robot, viewers)

    def _throttled(self, robot: RobotOutbox, throttle: Throttle, newest: int,
                   viewers: list[Client], message: Callable[[], dict[str, Any] | None]) -> bool:
        """Sends ``message()`` if item ``newest`` is due by ``throttle``; whether it went out.

        When it is not due yet, the robot is looked at again when it will be.
        """
        now = time.monotonic()
        wait = throttle.wait(newest, now)
        if wait is None:
            return False
        if not viewers or wait <= 0:
            throttle.mark(newest, now)
            self._send(viewers, message())
            return True
        if not throttle.later and self._loop is not None:
            throttle.later = True
            self._loop.call_later(wait, self._due, robot.namespace, throttle)
        return False

    def _due(self, namespace: str, throttle: Throttle) -> None:
        throttle.later = False
        if namespace in self.robots:
            self._request(namespace)

    def _build(self, robot: RobotOutbox) -> None:
        if robot.building or self._loop is None:
            return  # the build under way takes the newest message when it is done
        robot.building = True
        task = self._loop.create_task(self._build_maps(robot))
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)

    async def _build_maps(self, robot: RobotOutbox) -> None:
        source = robot.source
        try:
            while (message := source.take_map()) is not None:
                in_use = {other.map.key for other in self.robots.values() if other.map}
                stored, warnings = await in_thread(self.store.put, message, in_use)
                for warning in warnings:
                    source.warn("map", warning)
                if self.robots.get(source.namespace) is not robot:
                    return  # released meanwhile
                if (stored.key if stored else None) != (robot.map.key if robot.map else None):
                    robot.map = stored
                    self._send(self._viewers(), robot.map_ref())
                    self._changed()
        except ShutdownError:
            return  # the process exits: the map is not needed any more
        except Exception:
            log.exception("monitor: could not keep the map of robot %s", source.namespace)
        finally:
            robot.building = False

    # ------------------------------------------------------------------ to pages
    def _viewers(self) -> list[Client]:
        return [client for client in self._clients if client.map_view]

    @staticmethod
    def _send(clients: list[Client], message: dict[str, Any] | None) -> None:
        if message is None or not clients:
            return
        text = wire_text(message)
        for client in clients:
            client.send(text)

    def _send_warnings(self, robot: RobotOutbox, viewers: list[Client]) -> None:
        for kind, message, count in robot.source.warnings.due():
            self._send(viewers, {"t": "robot_warn", "ns": robot.source.namespace,
                                 "kind": kind, "message": message, "count": count})

    def view(self, client: Client, on: bool) -> None:
        """Makes ``client`` show the map (``on``) or not; a page that starts gets everything."""
        was, client.map_view = client.map_view, on
        self._follow_seen()
        if on and not was:
            self.resend(client)

    def _follow_seen(self) -> None:
        """Listens to the robots' detectors and trackers while some page shows the map only.

        A detector works only while someone listens to it.
        """
        wanted = any(client.map_view for client in self._clients)
        for robot in self.robots.values():
            robot.source.follow_detections(wanted)
            robot.source.follow_objects(wanted)

    def resend(self, client: Client) -> None:
        """Sends ``client``, if it shows the map, every robot's map, path, state and warnings."""
        if not client.map_view:
            return
        for robot in [robot for _name, robot in sorted(self.robots.items())]:
            source = robot.source
            if robot.map is not None:
                self._send([client], robot.map_ref())
            if source.path is not None:
                self._send([client], robot.path_message())
            self._send([client], robot.rs_message(scan=True, everything=True))
            self._send([client], robot.detections_message())
            self._send([client], robot.objects_message(within=OBJECTS_KEPT))
            for kind, message, count in source.warnings.latest():
                self._send([client], {"t": "robot_warn", "ns": source.namespace,
                                      "kind": kind, "message": message, "count": count})
