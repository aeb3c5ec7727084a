"""Tune glibc's malloc for cyborg's processes: few arenas, and large buffers kept for reuse.

**Arenas.** glibc gives each thread that meets contention an arena of its own (up to 8 per
core), and freed memory in one arena is not reused by threads allocating in another. A cyborg
process runs many threads — Zenoh's, one per node, the simulation loop, the tree's tick
thread, the web server — that all allocate messages, so the resident size grows for hours
without any Python object leaking: in an hour-long soak of `cyborg up` the process held
540 MiB and grew by 1 MiB a minute, while with two arenas it held 260 MiB and grew by 0.3 MiB
a minute (docs/benchmarks.md). :func:`limit_malloc_arenas` does what ``MALLOC_ARENA_MAX=2``
does, set from inside the process.

**Large buffers.** By default glibc serves a block of more than 32 MiB (and, until the first
such block is freed, of more than 128 KiB) with a fresh ``mmap`` and gives the memory back
when it is freed; it also hands free memory at the top of the heap back to the system. A
recorder of camera images allocates and frees several buffers of a frame's size (6 to 8 MB) for
every frame — the MCAP writer's chunk, its record, the payload — so each frame's bytes were
written into fresh pages, every 4 KiB page faulted in and zeroed by the kernel: more CPU than
copying the frame itself (docs/benchmarks.md, "Recording the camera"). :func:`keep_large_buffers`
serves blocks up to :data:`LARGE_BUFFER` from the heap and keeps up to :data:`KEPT_FREE` of
free memory there for the next frame, as ``MALLOC_MMAP_THRESHOLD_`` and
``MALLOC_TRIM_THRESHOLD_`` do. ``cyborg record`` and ``cyborg up --record-images`` call it;
the price is up to :data:`KEPT_FREE` of freed memory per arena that stays in the process.

An explicit setting in the environment wins; on other C libraries this does nothing.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import sys

ARENAS = 2
"""Malloc arenas for a cyborg process (glibc's default: 8 per core)."""
LARGE_BUFFER = 64 * 1024 * 1024
"""Blocks up to this size come from the heap once :func:`keep_large_buffers` was called."""
KEPT_FREE = 128 * 1024 * 1024
"""Free memory at the top of a heap that is kept for reuse rather than given back."""

_M_TRIM_THRESHOLD = -1  # mallopt's parameter numbers, from glibc's malloc.h
_M_MMAP_THRESHOLD = -3
_M_ARENA_MAX = -8


def _mallopt(parameter: int, value: int) -> bool:
    """Calls glibc's ``mallopt(parameter, value)``; False where there is none (musl, not Linux)."""
    if not sys.platform.startswith("linux"):
        return False
    name = ctypes.util.find_library("c")
    if name is None:
        return False
    try:
        mallopt = ctypes.CDLL(name).mallopt
    except (OSError, AttributeError):  # not glibc (musl has no mallopt)
        return False
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    mallopt.restype = ctypes.c_int
    return bool(mallopt(parameter, value))


def limit_malloc_arenas(arenas: int = ARENAS) -> bool:
    """Limits glibc's malloc to ``arenas`` arenas; True if it was done.

    Call it early, before the process starts its threads: arenas made already stay.
    """
    if "MALLOC_ARENA_MAX" in os.environ:
        return False
    return _mallopt(_M_ARENA_MAX, arenas)


def keep_large_buffers() -> bool:
    """Serves blocks up to :data:`LARGE_BUFFER` from the heap and keeps :data:`KEPT_FREE`.

    True if it was done; see the module for why a recorder of images wants it. It may be
    called at any time; it applies to every thread's allocations from then on.
    """
    if {"MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_"} & os.environ.keys():
        return False
    return _mallopt(_M_MMAP_THRESHOLD, LARGE_BUFFER) and _mallopt(_M_TRIM_THRESHOLD, KEPT_FREE)
