"""Blocking work handed from the web server's event loop to a worker thread, until shutdown.

The monitor's periodic work (discovering robots and trees, polling blackboards) and its map
builds run blocking calls in the loop's default executor (``asyncio.to_thread``). Once the
process or the loop shuts down, that executor takes no more work: Python's exit shuts every
executor down while daemon threads such as the monitor's web server still run, and
``asyncio.run`` shuts the loop's own down after the server stopped. :func:`in_thread` then
raises :class:`ShutdownError` instead of the executor's ``RuntimeError``, so its callers stop
quietly instead of logging a traceback; an exception of the work itself is raised as it is.
"""

from __future__ import annotations

import asyncio
import contextvars
import functools
from collections.abc import Callable
from typing import ParamSpec, TypeVar

P = ParamSpec("P")
R = TypeVar("R")


class ShutdownError(RuntimeError):
    """No more work can be handed to worker threads: the process or the loop is stopping."""


async def in_thread(func: Callable[P, R], /, *args: P.args, **kwargs: P.kwargs) -> R:
    """``func(*args, **kwargs)`` in the running loop's default executor, awaited.

    Like ``asyncio.to_thread`` (the context variables go along), but a refusal to take the work
    (the executor or the interpreter shut down) is :class:`ShutdownError`.
    """
    loop = asyncio.get_running_loop()
    call = functools.partial(contextvars.copy_context().run, func, *args, **kwargs)
    try:
        future = loop.run_in_executor(None, call)
    except RuntimeError as exc:  # raised before the work ever ran
        raise ShutdownError(f"no worker thread takes work now: {exc}") from exc
    return await future
