"""The robot commands a page may send from the map, and the rules they follow.

What MobileEyes, RViz's Nav2 panel and Foxglove's publish tool offer, as WebSocket commands
(each names its robot by ``ns``, the robot's namespace, e.g. ``/cyborg``):

=========  ==============================  ===============================================
``t``      fields                          what it calls on the bus
=========  ==============================  ===============================================
go         ns, goal                        ``move_to_goal`` to the map's goal ``goal``
go_pose    ns, pose: [x, y] or [x, y, θ]   ``move_to_goal`` to a pose (with θ: arrive
                                           facing θ)
home       ns                              ``move_to_goal`` to the map's home (below)
dock       ns                              ``dock``
undock     ns                              ``undock``
set_pose   ns, pose: [x, y] or [x, y, θ]   ``set_pose``: relocalise (without θ: keep the
                                           heading the robot has)
stop       ns                              ``stop``: ends the goal, docking, driving and a
                                           tour, and *stops* the robot's tree (below)
drive      ns, vx, wz                      ``cmd_vel`` (m/s, rad/s; clamped to the robot's
                                           ``TELEOP_MAX_SPEED``, ``TELEOP_MAX_TURN_RATE``)
tour       ns, points: [[x, y(, θ)], …]    the points in order (:mod:`cyborg.monitor.tour`)
=========  ==============================  ===============================================

**Home** is the map's first home object (ARNL's ``RobotHome``, where the robot starts), as a
pose goal with its heading; a map without one sends the robot to its goal named ``home`` (any
case); a map with neither refuses.

**Rules.** Every command but ``stop`` needs the control seat, as ``enable`` does. ``stop``
needs only that the page may control (loopback or the token): a stop always works, even while
another page holds the seat. A manual goal (``go``, ``go_pose``, ``home``, ``dock``,
``tour``) and driving by hand first *pause* the tree runner that drives the robot (its
``enable(false)``, as the Pause button), so the tree does not fight the operator; every page
hears ``{"t": "manual_pause", "tree", "ns"}``. A new goal or driving ends a tour; so does
``stop``.

**Stop stops.** ``stop`` calls, at once and side by side, the robot's ``stop`` service and the
``stop`` service of every tree runner that drives the robot (the runner's goal-sending is
halted as ``enable(false)`` halts it, and it latches ``stopped``,
:mod:`cyborg.interfaces.tree_runner`), so the tree cannot send the next goal a moment later.
The tree stays stopped until someone with the seat enables it again (the page's Resume, the
Run button, ``cyborg bt enable``); every page, one that comes later included, reads it as
``stopped`` in the ``runner`` and ``robots`` messages, and this monitor or any other shows the
same. The answer's ``stopped`` names the trees stopped. A page still driving by hand when
another stopped the robot is refused its drives until it lets go (a zero ``drive``).

**Answers.** Each command is answered with ``result`` (``req``, ``ok``, ``message``, and
``paused``: the tree paused for it, or null) once the call returns; a goal is answered when
the robot accepted it (its ``result`` adds ``goal``, the goal as the ``robot_result`` will name
it), and every page hears how it ended::

    {"t": "robot_result", "ns": "/cyborg", "command": "go", "goal": "Office",
     "outcome": "reached", "message": "reached the goal", "req": 7}

``outcome`` is ``reached``, ``failed``, ``canceled`` or ``no_path``; ``req`` is the request
number in the copy sent to the page that sent the goal, null in the others. ``drive`` is
answered only when refused, or when it carries a ``req``. A refusal (no seat, a bad field, the
robot's own refusal, no answer) is a ``result`` with ``ok: false``, the ``field`` at fault,
and a message located as errors are (``message 7 (go), field goal: ...``). When a page that
drove within the last ``TELEOP_TIMEOUT`` disconnects, the monitor publishes one zero twist to
that robot (never otherwise: a zero twist ends the robot's goal).
"""

from __future__ import annotations

import asyncio
import logging
import time
from collections.abc import Callable, Collection, Mapping
from functools import partial
from typing import Any

from cyborg.bus.msgs.cyborg_msgs.msg import MapObject
from cyborg.interfaces.robot import TELEOP_TIMEOUT
from cyborg.interfaces.tree_runner import robot_of_runner
from cyborg.monitor.client import Client
from cyborg.monitor.limits import check_namespace
from cyborg.monitor.off_loop import in_thread
from cyborg.monitor.refusal import RefusalError
from cyborg.monitor.robot_clients import (
    GoalEnd,
    MoveGoal,
    RobotCallError,
    RobotClients,
    cancel_later,
    wait_for_end,
)
from cyborg.monitor.robot_fields import (
    number_field,
    pose_field,
    short,
    tour_points,
)
from cyborg.monitor.robot_hub import RobotHub
from cyborg.monitor.seat import ControlSeat
from cyborg.monitor.source import ControlError, TreeSource
from cyborg.monitor.tour import Tour, Waypoint, point_text

log = logging.getLogger("cyborg.monitor")

ROBOT_COMMANDS = frozenset({"go", "go_pose", "home", "dock", "undock", "set_pose", "stop",
                            "drive", "tour"})
"""The commands of this module (:func:`cyborg.monitor.commands.handle` hands them here)."""
NAME_LIMIT = 200
"""Longest goal name a page may send."""


class RobotCommands:
    """Carries out the robot commands of pages; see the module docstring.

    ``clients`` are the hub's connected pages, ``seat`` its control seat, ``trees`` its tree
    sources by namespace and ``robots`` its robots; bus clients come from the function given
    to :meth:`use` (none until then: every command is refused). Runs on the server's event
    loop.
    """

    def __init__(self, clients: Collection[Client], seat: ControlSeat,
                 trees: Mapping[str, TreeSource], robots: RobotHub) -> None:
        self._pages, self._seat, self._trees, self._robots = clients, seat, trees, robots
        self._make: Callable[[str], RobotClients] | None = None
        self._bus: dict[str, RobotClients] = {}
        self._tours: dict[str, Tour] = {}
        self._driven: dict[int, tuple[str, float]] = {}
        """Connection number → (robot, when it last sent ``drive``, monotonic s)."""
        self._drives_stopped: set[tuple[int, str]] = set()
        """(Connection, robot) of drives a STOP ended, refused until the page lets go."""
        self._tasks: set[asyncio.Task[None]] = set()
        self._manual: dict[str, str] = {}
        """Trees paused for a manual goal → the robot they drive, until they run again."""

    def use(self, make_clients: Callable[[str], RobotClients]) -> None:
        """Acts on robots from now on, through ``make_clients(namespace)``."""
        self._make = make_clients

    # ------------------------------------------------------------------ commands
    async def handle(self, client: Client, kind: str,
                     command: dict[str, Any]) -> dict[str, Any] | None:
        """Carries out one command; what its ``result`` adds (``message``, ``paused``).

        None when nothing is to be answered (a ``drive`` without ``req``). Raises
        :class:`RefusalError` for a refusal.
        """
        self._seat.require(client.number, client.may_control, seat=kind != "stop")
        ns = self._namespace(command.get("ns"))
        bus = self._clients_for(ns)
        if kind == "stop":
            message, trees = await self._stop(client, ns, bus)
            return {"message": message, "paused": None, "stopped": trees}
        if kind == "drive":
            return await self._drive(client, ns, bus, command)
        if kind in ("set_pose", "undock"):
            return {"message": await self._adjust(ns, bus, kind, command), "paused": None}
        # a manual goal: its fields are checked before the tree is paused
        points: list[Waypoint] = []
        send: Callable[[], MoveGoal] | None
        what, send = "", None
        if kind == "tour":
            points = tour_points(command)
        elif kind == "go":
            goal = await self._goal_name(ns, bus, command.get("goal"))
            what, send = repr(goal), partial(bus.send_goal, name=goal)
        elif kind == "go_pose":
            x, y, theta = pose_field(command, "pose")
            what = point_text((x, y, theta))
            send = partial(bus.send_goal, pose=(x, y, theta or 0.0), use_heading=theta is not None)
        elif kind == "home":
            what, send = await self._home(ns, bus)
        paused = await self._pause_tree(ns)
        self._end_tour(ns, "replaced by a new goal")
        note = f"; the tree {paused} is paused for it" if paused else ""
        if kind == "dock":
            return {"message": await self._call(ns, bus, "dock") + note, "paused": paused}
        if kind == "tour":
            self._start_tour(ns, bus, points)
            return {"message": f"{ns}: a tour of {len(points)} points{note}", "paused": paused}
        assert send is not None
        try:
            moving = await in_thread(send)
        except RobotCallError as exc:
            raise RefusalError(str(exc)) from None
        self._follow(client, command.get("req"), ns, kind, what, moving)
        return {"message": f"{ns}: going to {what}{note}", "paused": paused, "goal": what}

    def _namespace(self, value: Any) -> str:
        if value is None:
            raise RefusalError("name the robot in ns (such as /cyborg)", "ns")
        try:
            ns = check_namespace(value)
        except ValueError as exc:
            raise RefusalError(str(exc), "ns") from None
        known = self._robots.robots.get(ns)
        if known is None:
            robots = ", ".join(sorted(self._robots.robots)) or "none"
            raise RefusalError(f"no robot {ns} on the bus (robots: {robots})", "ns")
        if not known.source.alive:
            raise RefusalError(f"the robot {ns} has left the bus", "ns")
        return ns

    def _clients_for(self, ns: str) -> RobotClients:
        """The bus clients for ``ns``, made on first use.

        Those of robots the hub no longer follows are withdrawn first, so robots that come and
        go cost nothing lasting.
        """
        for gone in [name for name in self._bus if name not in self._robots.robots]:
            self._end_tour(gone, "the robot left")
            self._bus.pop(gone).destroy()
        found = self._bus.get(ns)
        if found is None:
            if self._make is None:
                raise RefusalError("this monitor does not act on robots")
            found = self._bus[ns] = self._make(ns)
        return found

    async def _call(self, ns: str, bus: RobotClients, service: str) -> str:
        try:
            ok, message = await in_thread(bus.trigger, service)
        except RobotCallError as exc:
            raise RefusalError(str(exc)) from None
        if not ok:
            raise RefusalError(f"{ns}/{service} refused: {message}")
        return f"{ns}: {message}"

    async def _stop(self, client: Client, ns: str, bus: RobotClients) -> tuple[str, list[str]]:
        """Stops the robot and the trees that drive it, side by side; what it says, the trees.

        Drives of other pages in progress are refused until they let go (the page that stops
        lets go of its own).
        """
        self._end_tour(ns, "stopped")
        now = time.monotonic()
        self._drives_stopped |= {(number, ns) for number, (driven, when) in self._driven.items()
                                 if driven == ns and now - when < TELEOP_TIMEOUT
                                 and number != client.number}
        trees = [tree for tree in sorted(self._trees) if robot_of_runner(tree) == ns
                 and self._trees[tree].alive]
        robot, *halted = await asyncio.gather(
            self._call(ns, bus, "stop"),
            *(in_thread(self._trees[tree].stop) for tree in trees),
            return_exceptions=True)
        stopped = [tree for tree, done in zip(trees, halted, strict=True)
                   if not isinstance(done, BaseException)]
        for tree in stopped:  # stopped, no longer paused for a manual goal
            self._manual.pop(tree, None)
        failed = [f"the tree {tree} could not be stopped: {done}"
                  for tree, done in zip(trees, halted, strict=True)
                  if isinstance(done, BaseException)]
        said = [f"the tree {', '.join(stopped)} is stopped until someone resumes it"] \
            if stopped else []
        if isinstance(robot, BaseException):
            if not isinstance(robot, RefusalError):
                raise robot
            raise RefusalError("; ".join([str(robot), *said, *failed])) from None
        if failed:
            raise RefusalError("; ".join([robot, *said, *failed]))
        return "; ".join([robot, *said]), stopped

    async def _adjust(self, ns: str, bus: RobotClients, kind: str,
                      command: dict[str, Any]) -> str:
        if kind == "undock":
            return await self._call(ns, bus, "undock")
        x, y, theta = pose_field(command, "pose")
        if theta is None:  # keep the heading the robot has
            pose = self._robots.robots[ns].source.pose
            theta = float(pose[2]) if pose is not None else 0.0
        try:
            ok, message = await in_thread(bus.set_pose, x, y, theta)
        except RobotCallError as exc:
            raise RefusalError(str(exc)) from None
        if not ok:
            raise RefusalError(f"{ns}/set_pose refused: {message}", "pose")
        return f"{ns}: {message}"

    async def _drive(self, client: Client, ns: str, bus: RobotClients,
                     command: dict[str, Any]) -> dict[str, Any] | None:
        vx, wz = number_field(command, "vx"), number_field(command, "wz")
        if (client.number, ns) in self._drives_stopped:
            if vx or wz:
                raise RefusalError(f"{ns} was stopped while you drove it: let go, then "
                                        "drive again")
            self._drives_stopped.discard((client.number, ns))
        paused = None
        if vx or wz:
            paused = await self._pause_tree(ns)
            self._end_tour(ns, "driven by hand")
        vx, wz = bus.drive(vx, wz)
        self._driven[client.number] = (ns, time.monotonic())
        if command.get("req") is None:
            return None
        return {"message": f"{ns}: driving at {vx:.2f} m/s, {wz:.2f} rad/s", "paused": paused}

    async def _goal_name(self, ns: str, bus: RobotClients, name: Any) -> str:
        if not isinstance(name, str) or not name.strip() or len(name) > NAME_LIMIT:
            raise RefusalError(f"goal: the name of one of the map's goals (1 to "
                                    f"{NAME_LIMIT} characters), not {short(name)}", "goal")
        try:
            names = await in_thread(bus.goal_names)
        except RobotCallError as exc:
            raise RefusalError(str(exc)) from None
        if name not in names:
            listed = ", ".join(repr(known) for known in names[:20]) or "none"
            more = f" and {len(names) - 20} more" if len(names) > 20 else ""
            raise RefusalError(f"no goal {name[:80]!r} on the map of {ns} (goals: "
                                    f"{listed}{more})", "goal")
        return name

    async def _home(self, ns: str, bus: RobotClients) -> tuple[str, Callable[[], MoveGoal]]:
        stored = self._robots.robots[ns].map
        homes = [item for item in (stored.objects if stored else ())
                 if item["category"] == MapObject.HOME]
        if homes:
            x, y, theta = homes[0]["pose"]
            what = f"home {homes[0]['name'] or ''} {point_text((x, y, theta))}".replace("  ", " ")
            return what, partial(bus.send_goal, pose=(x, y, theta), use_heading=True)
        try:
            names = await in_thread(bus.goal_names)
        except RobotCallError as exc:
            raise RefusalError(str(exc)) from None
        named = next((name for name in names if name.lower() == "home"), None)
        if named is None:
            raise RefusalError(f"the map of {ns} has no home (no RobotHome, no goal "
                                    "named home)")
        return repr(named), partial(bus.send_goal, name=named)

    # ------------------------------------------------------------------ the tree
    async def _pause_tree(self, ns: str) -> str | None:
        """Pauses the running tree that drives ``ns``; its namespace, or None if none ran."""
        for tree in sorted(self._trees):
            source = self._trees[tree]
            if robot_of_runner(tree) != ns or not source.alive or source.enabled is not True:
                continue
            try:
                await in_thread(source.set_enabled, False)
            except ControlError as exc:
                raise RefusalError(f"the tree {tree} could not be paused, so nothing was "
                                        f"sent: {exc}") from None
            self._manual[tree] = ns
            self._broadcast({"t": "manual_pause", "tree": tree, "ns": ns})
            return tree
        return None

    def resend(self, client: Client) -> None:
        """Tells a page that just came which trees are still paused for a manual goal.

        A tree that runs again since (resumed from any page or the command line) is forgotten.
        """
        for tree, ns in list(self._manual.items()):
            source = self._trees.get(tree)
            if source is None or source.enabled is not False:
                del self._manual[tree]
                continue
            client.send({"t": "manual_pause", "tree": tree, "ns": ns})

    # ------------------------------------------------------------------ goals and tours
    def _follow(self, client: Client, req: Any, ns: str, kind: str, what: str,
                moving: MoveGoal) -> None:
        """Tells every page how the goal ends (``robot_result``), the sender with its ``req``."""
        async def tell() -> None:
            end = await wait_for_end(moving)
            message = {"t": "robot_result", "ns": ns, "command": kind, "goal": what,
                       "outcome": end.outcome, "message": end.message}
            self._broadcast({**message, "req": None}, only={client: {**message, "req": req}})

        self._keep(asyncio.get_running_loop().create_task(tell()))

    def _start_tour(self, ns: str, bus: RobotClients, points: list[Waypoint]) -> None:
        async def leg(point: Waypoint) -> GoalEnd:
            x, y, theta = point
            moving = await in_thread(bus.send_goal, pose=(x, y, theta or 0.0),
                                             use_heading=theta is not None)
            try:
                return await wait_for_end(moving)
            except asyncio.CancelledError:
                cancel_later(moving)
                raise

        tour = self._tours[ns] = Tour(ns, points, leg, self._broadcast)
        task = tour.start()
        task.add_done_callback(lambda _task: self._tours.pop(ns, None)
                               if self._tours.get(ns) is tour else None)
        self._keep(task)

    def _end_tour(self, ns: str, reason: str) -> None:
        tour = self._tours.pop(ns, None)
        if tour is not None:
            tour.cancel(reason)

    def _keep(self, task: asyncio.Task[None]) -> None:
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)

    def _broadcast(self, message: dict[str, Any],
                   only: dict[Client, dict[str, Any]] | None = None) -> None:
        """Queues ``message`` to every page; those in ``only`` get their own version."""
        for page in list(self._pages):
            page.send((only or {}).get(page, message))

    # ------------------------------------------------------------------ pages leaving
    def disconnected(self, client: Client) -> None:
        """A page left: one zero twist to the robot it drove, if it drove just now."""
        driven = self._driven.pop(client.number, None)
        self._drives_stopped = {stopped for stopped in self._drives_stopped
                                if stopped[0] != client.number}
        if driven is None or time.monotonic() - driven[1] >= TELEOP_TIMEOUT:
            return
        bus = self._bus.get(driven[0])
        if bus is not None:
            try:
                bus.drive(0.0, 0.0)
            except Exception:
                log.exception("monitor: could not stop %s after its driver left", driven[0])

    def destroy(self) -> None:
        """Ends tours and withdraws every robot's clients (the monitor is stopping)."""
        for ns in list(self._tours):
            self._end_tour(ns, "the monitor stopped")
        for bus in self._bus.values():
            bus.destroy()
        self._bus.clear()
