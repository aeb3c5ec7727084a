"""Keep a long-running cyborg process's memory flat: limit glibc's malloc arenas.

glibc gives each thread that meets contention an arena of its own (up to 8 per core), and
freed memory in one arena is not reused by threads allocating in another. A cyborg process
runs many threads — Zenoh's, one per node, the simulation loop, the tree's tick thread, the
web server — that all allocate messages, so the resident size grows for hours without any
Python object leaking: in an hour-long soak of `cyborg up` the process held 540 MiB and grew
by 1 MiB a minute, while with two arenas it held 260 MiB and grew by 0.3 MiB a minute
(docs/benchmarks.md). This is what ``MALLOC_ARENA_MAX=2`` does, set from inside the process.

An explicit ``MALLOC_ARENA_MAX`` in the environment wins; on other C libraries this does
nothing.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import sys

ARENAS = 2
"""Malloc arenas for a cyborg process (glibc's default: 8 per core)."""

_M_ARENA_MAX = -8  # mallopt's parameter number, from glibc's malloc.h


def limit_malloc_arenas(arenas: int = ARENAS) -> bool:
    """Limits glibc's malloc to ``arenas`` arenas; True if it was done.

    Call it early, before the process starts its threads: arenas made already stay.
    """
    if not sys.platform.startswith("linux") or "MALLOC_ARENA_MAX" in os.environ:
        return False
    name = ctypes.util.find_library("c")
    if name is None:
        return False
    try:
        libc = ctypes.CDLL(name)
        mallopt = libc.mallopt
    except (OSError, AttributeError):  # not glibc (musl has no mallopt)
        return False
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    mallopt.restype = ctypes.c_int
    return bool(mallopt(_M_ARENA_MAX, arenas))
