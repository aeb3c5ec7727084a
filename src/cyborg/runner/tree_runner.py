"""The tree runner on the bus: load a behavior3editor tree, tick it, publish what it does.

Under its namespace (``/cyborg/bt`` by default, as in 2018) it serves what
:mod:`cyborg.interfaces.tree_runner` describes (structure, active path, ``enabled``,
``stopped``, per-tick ``status`` while someone listens, ``services`` via
:mod:`cyborg.runner.service_states`; ``enable``, ``stop``, ``reload``), the per-node controls of
:mod:`cyborg.runner.tree_control`, and the parameter ``reload_timeout`` (wall seconds; 30).

**Services never wait on each other.** ``enable`` and ``stop`` are answered on a thread of
their own, the other control services on another; neither waits for ``reload`` (loaded in the
background, :mod:`cyborg.runner.background_reload`) or the node's own thread.

**Enable, disable, stop** (docs/controller.md). Disabling *halts* the tree (a MoveTo cancels its
goal); enabling starts it afresh; ``stop`` disables and latches ``stopped`` until
``enable(true)``. Ticks stop at once; the halt waits for the tick in progress, which a tick that
computes does not hold up (:mod:`cyborg.bt.tick_guard` interrupts it) and one waiting on a slow
robot may: ``enable`` then answers after :data:`HALT_WAIT` seconds (saying so) and
``enable(true)`` is refused until the halt is done. A tick past its limit (10 s) is
interrupted, logged with its node, and the tree disabled. A good reload replaces the tree
between two ticks, keeping the global blackboard and the hooks of nodes that still exist.

**Time.** The tree ticks on the wall clock, or on ``/clock`` with ``use_sim_time``. **Modes.**
Given a mode file (``*.toml``, docs/modes.md) instead of a tree file, the runner ticks a
:class:`~cyborg.modes.ModeMachine` and serves :mod:`cyborg.interfaces.modes` as well
(:mod:`cyborg.runner.mode_endpoints`). Everything above then concerns the current mode's tree,
published again whenever the mode changes (after the status of the tick that led to it, so watchers
never paint the tree left's statuses on the tree entered). A reload reads a mode file again; one
that fails republishes the ``mode`` state with the file's problems.
"""

from __future__ import annotations

import json
import logging
import threading
from pathlib import Path
from typing import Any

from cyborg.bt import (
    Blackboard,
    Clock,
    NodeRegistry,
    ServiceRegistry,
    TickLoop,
    Tree,
    default_registry,
    load_tree,
)
from cyborg.bt.problems import Problem, TreeLoadError
from cyborg.bt.snapshot import TickSnapshot
from cyborg.bt.tick_loop import DEFAULT_RATE, TICK_LIMIT
from cyborg.bus import Node, SimClock
from cyborg.bus.msgs.cyborg_msgs.msg import (
    BehaviorTree,
    BehaviorTreeNodes,
)
from cyborg.bus.msgs.cyborg_msgs.srv import ReloadTree, ReloadTree_Request, ReloadTree_Response
from cyborg.bus.msgs.std_msgs.msg import Bool
from cyborg.bus.msgs.std_srvs.srv import (
    SetBool,
    SetBool_Request,
    SetBool_Response,
    Trigger_Request,
    Trigger_Response,
)
from cyborg.bus.services import Responder
from cyborg.interfaces import tree_runner
from cyborg.modes import ModeMachine, Transition, Trigger, load_machine
from cyborg.robot.protocol import ROBOT, Robot
from cyborg.runner.background_reload import BackgroundReloads
from cyborg.runner.mode_endpoints import ModeEndpoints
from cyborg.runner.service_states import ServiceStatesPublisher
from cyborg.runner.status_message import status_message
from cyborg.runner.ticked import describe, mode_of, tree_of
from cyborg.runner.tree_control import TreeControl

log = logging.getLogger("cyborg.runner")

RELOAD_TIMEOUT = 30.0
"""Seconds (wall time) a reload may take before it is answered with an error."""
STILL_HALTING = ("; ticking has stopped and the tree halts when its current tick ends (a node "
                 "in it is still waiting, e.g. on the robot)")
"""What an ``enable(false)`` or ``stop`` answered before the halt adds."""
HALT_WAIT = 0.5
"""Seconds ``enable(false)`` waits for the halt before it answers (see ``set_enabled``)."""
MODE_FILE_SUFFIX = ".toml"
"""A file with this suffix is a mode file (docs/modes.md), any other a tree file."""
AFTER_A_TICK = (Trigger.CONDITION, Trigger.TIMEOUT)
"""Transitions the machine makes right after a tick, before the tick's listeners run."""


class TreeRunnerNode:
    """Runs one tree file on the bus; see the module docstring."""

    def __init__(self, node: Node, path: str | Path, *, tree: str | None = None,
                 rate_hz: float = DEFAULT_RATE, clock: Clock | None = None,
                 robot: Robot | None = None,
                 registry: NodeRegistry | None = None, enabled: bool = True,
                 reload_timeout: float = RELOAD_TIMEOUT,
                 services: ServiceRegistry | None = None,
                 tick_limit: float | None = TICK_LIMIT) -> None:
        """Load the tree (raises :class:`~cyborg.bt.TreeLoadError`), set up topics and services.

        :meth:`start` begins ticking. ``reload_timeout`` is the default of the node parameter
        of that name (a value given to the node at start-up wins). ``services`` are the
        services its composites may carry (default: the registered ones,
        :func:`~cyborg.bt.default_service_registry`). ``tick_limit`` (wall seconds) bounds a
        tick: one that overruns it is interrupted and the tree disabled (module docstring).
        """
        self.node, self.path, self.tree_choice = node, Path(path), tree
        self.registry = registry if registry is not None else default_registry()
        self.services = services
        self.clock = clock
        self.resources: dict[str, Any] = {ROBOT: robot} if robot is not None else {}
        self.ticked = self._load(self.path, Blackboard(resources=self.resources))
        """What the loop ticks: the tree, or the mode machine of a mode file."""
        self.runner: TickLoop[Tree | ModeMachine] = TickLoop(self.ticked, rate_hz=rate_hz,
                                                                tick_limit=tick_limit)
        self._enabled = enabled
        self._stopped = False
        self._active: tuple[str, ...] | None = None
        self._lock = threading.Lock()
        self._halting: threading.Thread | None = None  # halts the tree once its tick ends
        self._reloads = BackgroundReloads(self._load_next, self._install_saying,
                                          self._answer_reload)
        if "reload_timeout" not in node.parameters:
            node.parameters.declare("reload_timeout", float(reload_timeout), "seconds (wall "
                                    "time) a reload may take before it is answered with an "
                                    "error", limits=(0.01, 3600.0))
        self._structure = tree_runner.STRUCTURE.publisher(node)
        self._updates = tree_runner.ACTIVE_PATH.publisher(node)
        self._enabled_pub = tree_runner.ENABLED.publisher(node)
        self._stopped_pub = tree_runner.STOPPED.publisher(node)
        self._status = tree_runner.STATUS.publisher(node)
        self._service_states = ServiceStatesPublisher(node)
        stopping = node.callback_thread("enable")
        tree_runner.ENABLE.server(node, self._on_enable, callbacks=stopping)
        tree_runner.STOP.server(node, self._on_stop, callbacks=stopping)
        tree_runner.RELOAD.server(node, self._on_reload, deferred=True)
        self.control = TreeControl(node, lambda: self.tree,
                                   callbacks=node.callback_thread("control"))
        self.runner.add_listener(self._on_tick)
        self.runner.add_interrupt_listener(self._on_overrun)
        self.runner.add_service_listener(lambda _ran: self._service_states.look(self.tree))
        self.modes: ModeEndpoints | None = None
        self._structure_after_tick = False
        if isinstance(self.ticked, ModeMachine):
            self.modes = ModeEndpoints(node, self._machine)
            self._follow(self.ticked)
        self._publish_structure()
        self._publish_enabled()
        self._stopped_pub.publish(Bool(data=self._stopped))
        self._thread: threading.Thread | None = None

    @property
    def tree(self) -> Tree:
        """The tree that ticks: the runner's, or the current mode's."""
        ticked = self.ticked
        return ticked.tree if isinstance(ticked, ModeMachine) else ticked

    # ------------------------------------------------------------------ loading
    def _load(self, path: Path, blackboard: Blackboard) -> Tree | ModeMachine:
        if path.suffix == MODE_FILE_SUFFIX:
            return load_machine(path, registry=self.registry, clock=self.clock,
                                blackboard=blackboard, services=self.services)
        return load_tree(path, tree=self.tree_choice, registry=self.registry, clock=self.clock,
                         blackboard=blackboard, services=self.services)

    def _machine(self) -> ModeMachine:
        ticked = self.ticked
        assert isinstance(ticked, ModeMachine), "only a runner of a mode file serves modes"
        return ticked

    def _follow(self, machine: ModeMachine) -> None:
        """Publishes the machine's transitions and follows its trees with the controls."""
        machine.add_listener(self._on_transition)
        if self.modes is not None:
            self.modes.loaded()

    def _on_transition(self, transition: Transition) -> None:
        machine = self.ticked
        if not isinstance(machine, ModeMachine):
            return
        self.control.tree_replaced(machine.trees[transition.source],
                                   machine.trees[transition.target])
        self._active = None  # the next tick publishes its path (no lock: this may run in a tick)
        if transition.trigger in AFTER_A_TICK:
            self._structure_after_tick = True  # the tick's own status goes out first
        else:
            self._publish_structure()
        if self.modes is not None:
            self.modes.publish_transition(transition)

    @property
    def reload_timeout(self) -> float:
        """Seconds (wall time) a reload over the bus may take: the node parameter."""
        return float(self.node.parameters["reload_timeout"])

    def reload(self, path: str | Path | None = None) -> Tree:
        """Load ``path`` (default: the current file) and tick it from the next tick on.

        Returns the tree that now ticks (of a mode file: the initial mode's; the machine is
        :attr:`ticked`). Raises :class:`~cyborg.bt.TreeLoadError` (the old tree keeps running)
        on errors. This waits for the load, however long it takes; the ``reload`` service
        does not.
        """
        path = Path(path) if path else self.path
        self._install(self._load_next(path), path)
        return self.tree

    def _load_next(self, path: Path) -> Tree | ModeMachine:
        """Load ``path`` as the next tree: same globals and resources as the running one."""
        modes = isinstance(self.ticked, ModeMachine)
        if (path.suffix == MODE_FILE_SUFFIX) != modes:
            kind = "a mode file (*.toml)" if modes else "a tree file"
            raise TreeLoadError([Problem(f"this runner runs {kind}; it reloads only {kind}s",
                                         str(path), field="file")])
        old = self.tree.blackboard
        try:
            return self._load(path, Blackboard(old.globals, resources=old.resources))
        except TreeLoadError as exc:
            if self.modes is not None:
                self.modes.load_failed([str(problem) for problem in exc.problems
                                        if problem.is_error] or [str(exc)])
            raise

    def _install(self, ticked: Tree | ModeMachine, path: Path) -> Tree | ModeMachine:
        # between two ticks: may wait for one, so not under _lock (enable never waits on it)
        old_tree = self.tree
        self.runner.replace_tree(ticked)
        with self._lock:
            self.ticked, self.path, self._active = ticked, path, None
        tree = self.tree
        self.control.tree_replaced(old_tree, tree)
        if isinstance(ticked, ModeMachine):
            self._follow(ticked)
        self._publish_structure()
        if not self._enabled:  # no tick comes to tell of the new tree's services
            self._service_states.look(tree)
        log.info("reloaded %s: %s", path, describe(ticked))
        return ticked

    def _install_saying(self, ticked: Tree | ModeMachine, path: Path) -> str:
        return describe(self._install(ticked, path))

    # ------------------------------------------------------------------ running
    @property
    def enabled(self) -> bool:
        """Whether the tree is enabled, as ``enabled`` says; after a disable, a halt may pend."""
        return self._enabled

    @property
    def stopped(self) -> bool:
        """Whether :meth:`stop_tree` halted the tree and no enable has run it since."""
        return self._stopped

    def start(self) -> None:
        """Tick in a background thread; on simulated time, from the first ``/clock`` on."""
        if self._thread is not None:
            raise RuntimeError("the tree runner is already started")
        if not self._enabled:
            self.runner.pause()
        # named after the node: a fleet's log records name their robot by it (app.terminal)
        self._thread = threading.Thread(target=self._run, name=f"cyborg-tree {self.node.fq_name}",
                                        daemon=True)
        self._thread.start()

    def _run(self) -> None:
        clock = self.clock
        if isinstance(clock, SimClock) and not clock.started:
            log.info("waiting for /clock (use_sim_time)")
            while not clock.wait_for_time(1.0):
                if self.runner.stopped:
                    return
        self.runner.run()

    def set_enabled(self, enabled: bool, *, wait: float | None = None) -> bool:
        """Run (True) or halt and pause (False) the tree; see the module docstring.

        Disabling stops the ticks at once; the halt (a MoveTo cancels its goal) needs the tick
        that may be running to end first, which a node waiting on a slow robot can delay.
        ``wait`` bounds how long this waits for a pending halt (None: until it is done), and
        the result says whether the change is complete: False after disabling means the halt
        follows later; False when enabling means nothing changed, because the tree must not
        run again before its halt.
        """
        with self._lock:
            halting = self._halting
            if halting is not None:
                halting.join(wait if enabled else 0)
                if not halting.is_alive():
                    halting = self._halting = None
            if enabled == self._enabled:
                return halting is None
            if enabled:
                if halting is not None:
                    return False
                self._enabled = True
                self.runner.resume()
            else:
                self._enabled = False
                self.runner.pause()  # no tick starts from now on; the halt follows
                self._active = None
                halting = self._halting = threading.Thread(
                    target=self.runner.pause, kwargs={"halt": True}, daemon=True,
                    name="cyborg-tree-halt")
                halting.start()
        self._publish_enabled()
        if enabled:
            self._set_stopped(False)
        if enabled or halting is None:
            return True
        self._publish_active(())
        halting.join(wait)
        return not halting.is_alive()

    def stop_tree(self, *, wait: float | None = None) -> bool:
        """Halts the tree and keeps it halted until it is enabled again: a STOP.

        As ``set_enabled(False, wait=wait)`` (its result too), and ``stopped`` says so until
        :meth:`set_enabled` runs the tree again. Stopping a stopped tree changes nothing.
        """
        self._set_stopped(True)
        return self.set_enabled(False, wait=wait)

    def _set_stopped(self, stopped: bool) -> None:
        with self._lock:
            changed, self._stopped = stopped != self._stopped, stopped
        if changed:
            self._stopped_pub.publish(Bool(data=self._stopped))

    def stop(self) -> None:
        """Stop ticking and halt the tree (the robot stops); withdraws nothing from the bus."""
        self.runner.stop()
        if self._thread is not None:
            self._thread.join(5.0)

    def destroy(self) -> None:
        """Answer a pending reload, stop ticking (the tree halts) and destroy the node."""
        self._reloads.close()
        self.stop()
        self._service_states.close()
        self.control.destroy()
        self.node.destroy()

    # ------------------------------------------------------------------ publishing
    def _publish_structure(self) -> None:
        text = json.dumps(self.tree.structure.to_json(), separators=(",", ":"))
        self._structure.publish(BehaviorTree(tree=text))

    def _publish_enabled(self) -> None:
        self._enabled_pub.publish(Bool(data=self._enabled))

    def _publish_active(self, active: tuple[str, ...]) -> None:
        self._updates.publish(BehaviorTreeNodes(ids=list(active)))

    def _on_tick(self, snapshot: TickSnapshot) -> None:
        self._service_states.tick_ended(self.tree, snapshot)
        self._publish_tick(snapshot)
        if self._structure_after_tick:
            # the mode changed right after this tick: its path and status (of the tree left)
            # went out first, so no watcher paints them on the tree entered
            self._structure_after_tick = False
            self._active = None
            self._publish_structure()

    def _publish_tick(self, snapshot: TickSnapshot) -> None:
        active = tuple(snapshot.active)
        if active != self._active:
            self._active = active
            self._publish_active(active)
        tree = self.tree
        if self._status.subscription_count() == 0:
            tree.timing = False  # from the next tick on, nodes run untimed again
            return  # nobody listens: skip building the message
        tree.timing = True  # per-node timings from the next tick on
        self._status.publish(status_message(snapshot, self.mode_of(snapshot)))

    def mode_of(self, snapshot: TickSnapshot) -> str:
        """The mode whose tree made ``snapshot`` (a tick listener's); empty for a plain tree."""
        return mode_of(self.ticked, snapshot)

    def tree_of(self, snapshot: TickSnapshot) -> Tree:
        """The tree that made ``snapshot`` (a tick listener's); see :func:`ticked.tree_of`."""
        return tree_of(self.ticked, snapshot)

    def _on_overrun(self, _reason: str) -> None:
        """A tick overran its limit: the loop halted the tree and paused; it is disabled now."""
        with self._lock:
            self._enabled, self._active = False, None
        self._publish_enabled()
        self._publish_active(())

    def _on_enable(self, request: SetBool_Request) -> SetBool_Response:
        on = bool(request.data)
        done = self.set_enabled(on, wait=HALT_WAIT)
        response = SetBool.Response
        if on and not done:
            return response(success=False, message=(
                "not enabled: the tree is still halting, because the tick before the disable "
                "has not ended (a node in it is waiting, e.g. on the robot); try again"))
        message = "enabled" if self._enabled else "disabled"
        return response(success=True, message=message + ("" if done else STILL_HALTING))

    def _on_stop(self, _request: Trigger_Request) -> Trigger_Response:
        done = self.stop_tree(wait=HALT_WAIT)
        message = "stopped: the tree is halted until it is enabled again"
        return Trigger_Response(success=True, message=message + ("" if done else STILL_HALTING))

    def _on_reload(self, request: ReloadTree_Request,
                   responder: Responder[ReloadTree_Response]) -> None:
        """Start loading in the background and return at once (deferred: the load answers)."""
        path = Path(request.path) if request.path else self.path
        self._reloads.request(path, responder, self.reload_timeout)

    def _answer_reload(self, responder: Responder[ReloadTree_Response], success: bool,
                       message: str) -> None:
        responder.reply(ReloadTree.Response(success=success, message=message))

