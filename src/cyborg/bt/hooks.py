"""Per-node control of a running tree: disable a subtree, force a result, breakpoints, step.

One hook model covers what a monitor needs (Groot2 calls these hooks too)::

    hooks = tree.hooks
    hooks.disable("a3f…", FAILURE)        # the node's subtree is not ticked; it returns FAILURE
    hooks.force("b71…", SUCCESS, once=True)  # the node ticks, its result is replaced, once
    hooks.breakpoint("c09…")              # the tick stops before the node ticks …
    hooks.paused_at                       # … "c09…", until
    hooks.resume()                        # the tick goes on (hooks.step(): stop at the next node)
    hooks.clear("a3f…")                   # back to normal

* **Disable** (a "pre, replace" hook): the node is not ticked, nor anything below it; it returns
  the chosen status (SUCCESS or FAILURE). A RUNNING subtree is halted when it is disabled, so an
  action below it cancels what it started.
* **Force**: the node ticks as usual and its result is replaced (fault injection). With
  ``once`` the hook goes away after one use.
* **Breakpoint**: the ticking thread waits before the node ticks until :meth:`TreeHooks.resume`,
  :meth:`TreeHooks.step` or :meth:`TreeHooks.release`. :meth:`TreeHooks.step` lets the tick go on
  to the next node about to tick and stops there.

Every hook has an ``owner`` (a name chosen by whoever set it, e.g. the monitor's bus identity);
:meth:`TreeHooks.clear_owner` removes all of an owner's hooks when it goes away. Hooks are keyed
by node id, so they survive a reload of the same tree. A hooked node gets a wrapped
``execute``; nodes without hooks run exactly as before, at no extra cost.

**Timing.** With ``hooks.timing = True`` every node gets the wrapped ``execute`` and each visit's
wall time (the node and its subtree, breakpoint waits left out) goes into the tick's snapshot
(:attr:`~cyborg.bt.snapshot.TickSnapshot.visit_durations`); monitors show it per node.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from enum import StrEnum
from time import perf_counter
from typing import TYPE_CHECKING

from cyborg.bt.status import FAILURE, RUNNING, SUCCESS, Status

if TYPE_CHECKING:
    from cyborg.bt.node import Node


class HookMode(StrEnum):
    DISABLE = "disable"
    FORCE = "force"
    BREAKPOINT = "breakpoint"


@dataclass(frozen=True)
class Hook:
    """What to do at one node."""

    node: str
    """The node's id (its ``uid``)."""
    mode: HookMode
    status: Status = SUCCESS
    """The status a disabled node returns, or a forced node's result."""
    once: bool = False
    """Remove the hook after it was used once (force and breakpoint)."""
    owner: str = ""
    """Who set it; :meth:`TreeHooks.clear_owner` removes an owner's hooks."""


ALLOWED = {
    HookMode.DISABLE: (SUCCESS, FAILURE),
    HookMode.FORCE: (SUCCESS, FAILURE, RUNNING),
    HookMode.BREAKPOINT: (SUCCESS, FAILURE, RUNNING),
}


class HookError(ValueError):
    """A hook that cannot be set; the message names the node and the reason."""


class NodeHook:
    """What a hooked node carries: its hook, and the ``execute`` that applies it."""

    __slots__ = ("hook", "node", "owner")

    def __init__(self, owner: TreeHooks, node: Node, hook: Hook | None) -> None:
        self.owner, self.node, self.hook = owner, node, hook

    def execute(self) -> Status:
        """Stands in for ``node.execute`` while the node is hooked (or the tree is timed)."""
        owner = self.owner
        if not owner.timing:
            return self.apply()
        started, waited = perf_counter(), owner.waited
        status = self.apply()
        elapsed = perf_counter() - started - (owner.waited - waited)
        record = self.node._record
        record.durations[len(record.visits) - 1] = elapsed
        return status

    def apply(self) -> Status:
        """Tick the node with its hook applied."""
        node = self.node
        replaced = self.before(node)
        if replaced is not None:
            return node._skip(replaced)
        status = type(node).execute(node)
        forced = self.after(node, status)
        if forced is not status:
            node._replace_result(status, forced)
        return forced

    def before(self, node: Node) -> Status | None:
        """Called before the node ticks; a status means "do not tick, return this"."""
        hooks, hook = self.owner, self.hook
        if hooks.stepping or (hook is not None and hook.mode is HookMode.BREAKPOINT):
            hooks.wait_at(node, hook)
        if hook is not None and hook.mode is HookMode.DISABLE:
            return hook.status
        return None

    def after(self, node: Node, status: Status) -> Status:
        hook = self.hook
        if hook is None or hook.mode is not HookMode.FORCE:
            return status
        if hook.once:
            self.owner.clear(hook.node)
        return hook.status


class TreeHooks:
    """The hooks of one tree (``tree.hooks``); safe to change from any thread."""

    def __init__(self, nodes: Iterable[Node]) -> None:
        self._nodes = {node.uid: node for node in nodes}
        self._hooks: dict[str, Hook] = {}
        self._lock = threading.Condition()
        self._released = 0  # bumped to let waiting ticks go on
        self.stepping = False
        self._timing = False
        self.waited = 0.0
        """Seconds ticks have spent waiting at breakpoints (kept out of the timings)."""
        self.paused_at: str | None = None
        """Id of the node a tick is waiting before, or None."""
        self.listeners: list[Callable[[], None]] = []
        """Called (from the thread that made the change) whenever hooks or the pause change."""

    # ------------------------------------------------------------------ setting
    def set(self, hook: Hook) -> None:
        """Set (or replace) the hook of ``hook.node``; :class:`HookError` if it cannot be."""
        node = self._nodes.get(hook.node)
        if node is None:
            raise HookError(f"no node with id {hook.node!r} in the tree")
        if hook.status not in ALLOWED[hook.mode]:
            allowed = " or ".join(status.label for status in ALLOWED[hook.mode])
            raise HookError(f"node {hook.node}: a {hook.mode.value} hook returns {allowed}, "
                            f"not {hook.status.label}")
        with self._lock:
            self._hooks[hook.node] = hook
            self._attach(node, hook)
        self._changed()

    def disable(self, uid: str, status: Status = FAILURE, *, owner: str = "") -> None:
        self.set(Hook(uid, HookMode.DISABLE, status, owner=owner))

    def force(self, uid: str, status: Status, *, once: bool = False, owner: str = "") -> None:
        self.set(Hook(uid, HookMode.FORCE, status, once=once, owner=owner))

    def breakpoint(self, uid: str, *, once: bool = False, owner: str = "") -> None:
        self.set(Hook(uid, HookMode.BREAKPOINT, once=once, owner=owner))

    def clear(self, uid: str) -> bool:
        """Remove the hook of node ``uid``; False if it had none."""
        with self._lock:
            hook = self._hooks.pop(uid, None)
            if hook is None:
                return False
            self._attach(self._nodes[uid], None)
            if self.paused_at == uid and not self.stepping:
                self._release_locked()
        self._changed()
        return True

    def clear_owner(self, owner: str) -> list[str]:
        """Remove every hook set by ``owner``; returns the node ids that had one."""
        ids = [uid for uid, hook in list(self._hooks.items()) if hook.owner == owner]
        for uid in ids:
            self.clear(uid)
        return ids

    def clear_all(self) -> None:
        for uid in list(self._hooks):
            self.clear(uid)
        self.release()

    # ------------------------------------------------------------------ reading
    def hooks(self) -> list[Hook]:
        """Every hook set, in tree order."""
        order = {uid: index for index, uid in enumerate(self._nodes)}
        return sorted(self._hooks.values(), key=lambda hook: order[hook.node])

    def get(self, uid: str) -> Hook | None:
        return self._hooks.get(uid)

    # ------------------------------------------------------------------ timing
    @property
    def timing(self) -> bool:
        """Whether every visit is timed (see the module docstring)."""
        return self._timing

    @timing.setter
    def timing(self, on: bool) -> None:
        with self._lock:
            self._timing = bool(on)
            for uid, node in self._nodes.items():
                self._attach(node, self._hooks.get(uid))

    # ------------------------------------------------------------------ pausing
    def wait_at(self, node: Node, hook: Hook | None) -> None:
        """Called in the ticking thread: wait before ``node`` until released."""
        started = perf_counter()
        with self._lock:
            if self.stepping:
                self.stepping = False
                self._detach_steps()
            ticket = self._released
            self.paused_at = node.uid
        self._changed()
        with self._lock:
            while self._released == ticket:
                self._lock.wait()
            self.paused_at = None
            self.waited += perf_counter() - started
        if hook is not None and hook.once and hook.mode is HookMode.BREAKPOINT:
            self.clear(hook.node)
        self._changed()

    def resume(self) -> bool:
        """Let a tick waiting at a breakpoint go on; False if none was waiting."""
        with self._lock:
            waiting = self.paused_at is not None
            self._release_locked()
        return waiting

    def step(self) -> bool:
        """Let a waiting tick go on to the next node about to tick, and stop there.

        False (and nothing happens) when no tick is waiting.
        """
        with self._lock:
            if self.paused_at is None:
                return False
            self.stepping = True
            for node in self._nodes.values():
                if node.hook is None:
                    self._attach(node, None)
            self._release_locked()
        return True

    def release(self) -> None:
        """Let any waiting tick run to its end (used when the runner pauses or stops)."""
        with self._lock:
            if self.stepping:
                self.stepping = False
                self._detach_steps()
            self._release_locked()

    # ------------------------------------------------------------------ moving to a new tree
    def carry_to(self, other: TreeHooks) -> list[str]:
        """Set this tree's hooks on ``other`` where the node ids still exist; returns the ids
        of hooks that were dropped."""
        dropped = []
        for hook in self.hooks():
            try:
                other.set(hook)  # hooks are frozen: the same one can serve both trees
            except HookError:
                dropped.append(hook.node)
        return dropped

    # ------------------------------------------------------------------ internals
    def _attach(self, node: Node, hook: Hook | None) -> None:
        if hook is None and not self.stepping and not self._timing:
            node.hook = None
            node.__dict__.pop("execute", None)
        else:
            attached = node.hook = NodeHook(self, node, hook)
            node.execute = attached.execute  # type: ignore[method-assign]

    def _detach_steps(self) -> None:
        for node in self._nodes.values():
            attached = node.hook
            if attached is not None and attached.hook is None and not self._timing:
                node.hook = None
                node.__dict__.pop("execute", None)

    def _release_locked(self) -> None:
        self._released += 1
        self._lock.notify_all()

    def _changed(self) -> None:
        for listener in list(self.listeners):
            listener()
