"""Reloading a tree without holding anyone up: each load on a thread of its own, with a timeout.

The tree runner's ``reload`` service used to load on the node's thread, so a file that blocks
(a FIFO nobody writes) or explodes (subtrees that double at every level) held that thread — and
with it every other service of the node, ``enable`` included — for as long as the load ran.
:class:`BackgroundReloads` takes a request, returns at once, and answers it later from another
thread with the first of:

* the load's end: a good tree is installed (``install``) and reported, a bad one is rejected
  with its problems;
* the timeout (wall seconds): ``reload timed out: loading PATH did not finish within N s
  (reload_timeout); the tree that was running keeps running``;
* :meth:`BackgroundReloads.close` (the runner stops).

A Python thread cannot be killed, so a load that timed out goes on in the background; whatever
it ends with is *discarded* (logged), never installed behind the back of a caller who was told
the old tree runs. To keep hanging files from piling up threads and memory, one reload runs at
a time (another one is refused at once, not queued), and while :data:`STUCK_RELOADS` timed-out
loads have not ended, new ones are refused until the runner restarts. The tree loader's own caps
(regular files only, size, nesting, node instances) bound what a single load can cost.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Generic, TypeVar

from cyborg.bt import TreeLoadError
from cyborg.bus.services import Responder

log = logging.getLogger("cyborg.runner")

STUCK_RELOADS = 2
"""Timed-out loads that may still be running before further reloads are refused."""

Answer = Callable[[Responder, bool, str], None]
Loaded = TypeVar("Loaded")
"""What a reload builds: a tree, or a mode machine."""
"""``answer(responder, success, message)``: reply to a reload request."""


@dataclass(eq=False)
class _Reload:
    """One reload request, loading in the background."""

    path: Path
    responder: Responder
    timeout: float
    """Seconds (wall time) it may take, as configured when it was asked for."""
    started: float = field(default_factory=time.monotonic)
    timer: threading.Timer | None = None
    settled: bool = False
    """Answered: by the load's end, its timeout or the runner's end, whichever came first."""


class BackgroundReloads(Generic[Loaded]):
    """Reload requests of one tree runner; see the module docstring.

    ``load(path)`` builds the next tree (raises :class:`~cyborg.bt.TreeLoadError`),
    ``install(tree, path)`` makes it the running one and says what was loaded, ``answer``
    replies to a request.
    """

    def __init__(self, load: Callable[[Path], Loaded], install: Callable[[Loaded, Path], str],
                 answer: Answer) -> None:
        self._load, self._install, self._answer = load, install, answer
        self._lock = threading.Lock()
        self._loading: _Reload | None = None
        self._stuck: set[_Reload] = set()  # timed out, still loading
        self._closed = False

    def request(self, path: Path, responder: Responder, timeout: float) -> None:
        """Start loading ``path`` and return at once; ``responder`` is answered later."""
        job = _Reload(path, responder, timeout)
        with self._lock:
            refusal = self._refusal()
            if refusal is None:
                self._loading = job
        if refusal is not None:
            log.warning("reload of %s refused: %s", path, refusal)
            self._answer(responder, False, f"reload refused: {refusal}")
            return
        job.timer = threading.Timer(timeout, self._timed_out, (job,))
        job.timer.daemon = True
        job.timer.start()
        threading.Thread(target=self._run, args=(job,), daemon=True,
                         name=f"cyborg-reload:{path.name[:40]}").start()

    def close(self) -> None:
        """Answer a pending request (nothing was loaded) and refuse new ones."""
        with self._lock:
            self._closed = True
            pending = self._loading
        if pending is not None and self._settle(pending):
            self._answer(pending.responder, False,
                         "the tree runner is shutting down; nothing was loaded")

    def _refusal(self) -> str | None:
        """Why a new reload cannot start now (called holding the lock), or None."""
        busy, stuck = self._loading, len(self._stuck)
        if self._closed:
            return "the tree runner is shutting down"
        if busy is not None:
            return (f"still loading {busy.path} (for {time.monotonic() - busy.started:.1f} s): "
                    "one reload at a time; try again when it has been answered")
        if stuck >= STUCK_RELOADS:
            return (f"{stuck} earlier reloads timed out and are still loading in the "
                    "background; restart the tree runner to load another file")
        return None

    def _run(self, job: _Reload) -> None:
        tree: Loaded | None = None
        message = ""
        try:
            tree = self._load(job.path)
        except TreeLoadError as exc:
            message = "\n".join(str(problem) for problem in exc.problems) or str(exc)
        except Exception as exc:  # a node's constructor failed in a way the loader let through
            log.error("reload of %s: %s: %s", job.path, type(exc).__name__, exc, exc_info=True)
            message = f"{type(exc).__name__}: {exc}"
        if not self._settle(job):
            log.warning("the reload of %s ended after %.1f s, after its timeout (or the "
                        "runner's end): its result is discarded; the tree that runs is "
                        "unchanged", job.path, time.monotonic() - job.started)
            return
        if tree is None:
            self._answer(job.responder, False, message)
            return
        try:
            loaded = self._install(tree, job.path)
        except Exception as exc:
            log.exception("installing the tree reloaded from %s failed", job.path)
            self._answer(job.responder, False, f"{type(exc).__name__}: {exc}")
            return
        self._answer(job.responder, True, f"loaded {loaded} from {job.path}")

    def _timed_out(self, job: _Reload) -> None:
        if not self._settle(job, timed_out=True):
            return
        log.warning("the reload of %s did not finish within %g s; the tree that was running "
                    "keeps running", job.path, job.timeout)
        self._answer(job.responder, False,
                     f"reload timed out: loading {job.path} did not finish within "
                     f"{job.timeout:g} s (reload_timeout); the tree that was running keeps "
                     "running")

    def _settle(self, job: _Reload, *, timed_out: bool = False) -> bool:
        """Claims the right to answer ``job``; True for the first of its end, timeout and close.

        A timed-out job stays counted as stuck until its load ends.
        """
        with self._lock:
            if self._loading is job:
                self._loading = None
            if job.settled:
                self._stuck.discard(job)
                return False
            job.settled = True
            if timed_out:
                self._stuck.add(job)
            elif job.timer is not None:
                job.timer.cancel()
            return True
