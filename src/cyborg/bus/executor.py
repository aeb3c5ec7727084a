"""Where a node's callbacks run: one thread per node, one callback at a time.

Messages arrive on Zenoh's threads, or on a publisher's thread for a node of the same process;
either way they are queued here, so that a node's code never runs two callbacks at once, runs
them on its own thread (never on a publisher's), and a slow callback never stalls the network
or a publisher. The one exception is opted in per subscription
(``create_subscription(..., inline=True)``): an in-process message may then be handed over
directly on the publisher's thread while the node is idle, as nodelets did (see
:meth:`CallbackThread.try_inline`).

An exception in a callback is logged with its traceback — once per callback, then counted — and
the node keeps running.

A node may give some of its callbacks a thread of their own (ROS 2's callback groups, each with
its executor): :meth:`CallbackThread.route` sends what one entity submits to another
:class:`CallbackThread`, so a slow callback on the node's thread never delays them — the tree
runner's stop button is served this way (:meth:`cyborg.bus.Node.create_service`).
"""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Callable
from typing import Any

log = logging.getLogger("cyborg.bus")

_STOP = object()


class CallbackThread:
    """Runs submitted callables in order on one daemon thread.

    ``name`` (the node's full name) names the thread, ``cyborg-node<name>``, and the log lines.
    """

    def __init__(self, name: str) -> None:
        self.name = name
        self.errors = 0
        """Callbacks that raised so far."""
        self._reported: set[str] = set()
        self._queue: queue.SimpleQueue[Any] = queue.SimpleQueue()
        self._busy = threading.Lock()  # held while one of this node's callbacks runs
        self._routes: dict[int, tuple[object, CallbackThread]] = {}  # id(owner) -> its thread
        self._thread = threading.Thread(target=self._run, name=f"cyborg-node{name}",
                                         daemon=True)
        self._thread.start()

    def route(self, owner: object, thread: CallbackThread) -> None:
        """Run the callbacks ``owner`` submits here on ``thread`` instead.

        The callbacks are ``owner``'s bound methods (as a service server submits its handler);
        they run in their order, one at a time.
        """
        self._routes[id(owner)] = (owner, thread)

    def unroute(self, owner: object) -> None:
        """Forget ``owner``'s route (it was destroyed): the route would keep it alive."""
        entry = self._routes.get(id(owner))
        if entry is not None and entry[0] is owner:
            del self._routes[id(owner)]

    def _routed(self, function: Callable[..., object]) -> CallbackThread | None:
        owner = getattr(function, "__self__", None)
        entry = self._routes.get(id(owner)) if owner is not None else None
        return entry[1] if entry is not None and entry[0] is owner else None

    def submit(self, function: Callable[..., object], *args: Any) -> None:
        """Queue ``function(*args)`` to run on this thread (or its owner's route); any thread."""
        thread = self._routed(function) if self._routes else None
        if thread is not None:
            thread.submit(function, *args)
            return
        self._queue.put((function, args))

    def in_thread(self) -> bool:
        """Whether the caller is running on this thread."""
        return threading.current_thread() is self._thread

    def _run(self) -> None:
        while True:
            item = self._queue.get()
            if item is _STOP:
                return
            function, args = item
            with self._busy:
                self.call(function, *args)

    def flush(self, timeout: float = 5.0) -> bool:
        """Wait until every callback queued here before this call has run.

        Returns False if that takes more than ``timeout`` seconds; raises RuntimeError when
        called on this thread itself, which would wait forever.

        A message published in this process is queued to the subscribing node's thread, so
        once ``subscriber_node.callbacks.flush()`` returns True its callback has seen it (a
        test that moves a fake clock between messages waits like this). Callbacks routed to
        another thread are that thread's to flush.
        """
        if self.in_thread():
            raise RuntimeError(f"node {self.name}: flush on its own thread would wait forever")
        done = threading.Event()
        self._queue.put((done.set, ()))
        return done.wait(timeout)

    def try_inline(self, function: Callable[..., object], *args: Any) -> bool:
        """Run ``function`` now on the caller's thread if this node is idle with nothing queued.

        Only for subscriptions made with ``inline=True``: in-process delivery then skips a
        thread switch (tens of microseconds); the node still runs one callback at a time, and
        queued callbacks keep their order. Returns False, having run nothing, otherwise.
        """
        thread = self._routed(function) if self._routes else None
        if thread is not None:
            return thread.try_inline(function, *args)
        if not self._queue.empty() or not self._busy.acquire(blocking=False):
            return False
        try:
            self.call(function, *args)
        finally:
            self._busy.release()
        return True

    def call(self, function: Callable[..., object], *args: Any) -> object:
        """Run ``function`` now, containing and logging what it raises."""
        try:
            return function(*args)
        except Exception as exc:
            self.errors += 1
            where = getattr(function, "__qualname__", repr(function))
            if where not in self._reported:
                self._reported.add(where)
                log.error("node %s: callback %s raised %s: %s (further errors of this "
                          "callback are only counted)", self.name, where,
                          type(exc).__name__, exc, exc_info=True)
            return None

    def close(self, timeout: float = 2.0) -> None:
        """Finish the callback running now, drop the rest, stop the thread."""
        if not self._thread.is_alive():
            return
        while True:  # pending callbacks are dropped: the node is going away
            try:
                self._queue.get_nowait()
            except queue.Empty:
                break
        self._queue.put(_STOP)
        if not self.in_thread():
            self._thread.join(timeout)
