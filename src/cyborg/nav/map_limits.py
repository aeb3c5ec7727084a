"""Caps on what one map may cost: bytes read, grid cells, drawing work, objects.

A map arrives from a file anyone may have written, or through the ``load_map_file`` service
from any client on the bus. Before it can take the robot's memory or its time, each of these is
checked, with an error that names the file, what was too large, the cap and how to raise it:

=========================  ===========  ===========================================================
what                       default      environment variable to raise it
=========================  ===========  ===========================================================
file size                  8 MiB        ``CYBORG_MAP_MAX_BYTES`` (glassgarden.map is 1.25 MB; a
                                        file at the cap reads in about 3 s, 0.3 GB)
grid cells                 10,000,000   ``CYBORG_MAP_MAX_CELLS``: the extent plus a 1 m margin, at
                                        the grid's resolution (5 cm for the planner and the
                                        simulator: 25,000 m²; about 0.5 GB and 2.5 s to
                                        build in the simulator)
drawing work               8 x cells    the same variable: cells visited while drawing walls,
                                        forbidden lines and areas (many long walls across a map)
Cairn, MapInfo and other   10,000 each  ``CYBORG_MAP_MAX_OBJECTS`` (glassgarden.map has 41 cairns
header lines                            and a few dozen header lines)
=========================  ===========  ===========================================================

Only regular files are read (a FIFO would wait for a writer forever, ``/dev/zero`` never ends),
and never more than the cap. Coordinates have their own, fixed bound
(:data:`cyborg.nav.map_syntax.MAX_COORDINATE_MM`).
"""

from __future__ import annotations

import math
import os
import stat
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np

from cyborg.nav.map_objects import MapObject
from cyborg.nav.map_syntax import MapError

DEFAULT_RESOLUTION = 0.05
"""Metres per cell of the grids built from a map by default (the planner's and the simulator's)."""
GRID_MARGIN = 1.0
"""Metres of free space a grid adds around the map's extent."""
DRAWING_FACTOR = 8
"""Cells that drawing may visit, as a multiple of the cell cap."""
CHUNK = 1 << 20
"""Cells or samples drawn at a time, which bounds the memory drawing needs beside the grid."""

_VARIABLES = {"max_bytes": "CYBORG_MAP_MAX_BYTES", "max_cells": "CYBORG_MAP_MAX_CELLS",
              "max_objects": "CYBORG_MAP_MAX_OBJECTS"}


@dataclass(frozen=True)
class MapLimits:
    """The caps of the module's table; :func:`map_limits` reads them from the environment.

    ``max_bytes`` caps the file size, ``max_cells`` the grid cells (and so the drawing work),
    ``max_objects`` each kind of header line.
    """

    max_bytes: int = 8 * 1024 * 1024
    max_cells: int = 10_000_000
    max_objects: int = 10_000


def map_limits() -> MapLimits:
    """The caps in force: the defaults, or positive whole numbers from the environment.

    Raises MapError, naming the variable, when one is set to anything else.
    """
    values: dict[str, int] = {}
    for name, variable in _VARIABLES.items():
        text = os.environ.get(variable, "").strip().replace("_", "")
        if not text:
            continue
        if not text.isdigit() or int(text) <= 0:
            raise MapError(variable, 0, f"expected a positive whole number, not {text[:30]!r}")
        values[name] = int(text)
    return MapLimits(**values)


# ---------------------------------------------------------------------- the file
def read_capped(path: str | Path, max_bytes: int) -> bytes:
    """The bytes of a regular file of at most ``max_bytes``; MapError otherwise.

    The file is opened without blocking (a FIFO with no writer would hold the caller), its type
    is checked on the open descriptor, and no more than ``max_bytes + 1`` bytes are ever read.
    """
    source = str(path)
    flags = os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NOCTTY", 0)
    try:
        descriptor = os.open(path, flags)
    except (OSError, ValueError) as exc:  # ValueError: a NUL byte in the path
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise MapError(source, 0, f"cannot read the map: {reason}") from exc
    try:
        status = os.fstat(descriptor)
        mode, size = status.st_mode, status.st_size
        if not stat.S_ISREG(mode):
            kind = ("a folder" if stat.S_ISDIR(mode) else "a FIFO" if stat.S_ISFIFO(mode)
                    else "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode) else "a socket")
            raise MapError(source, 0, f"not a regular file ({kind}); a map is read from a file")
        if size > max_bytes:
            raise _too_large(source, f"{size:,} bytes", max_bytes)
        chunks: list[bytes] = []
        total = 0
        while chunk := os.read(descriptor, max_bytes + 1 - total):
            chunks.append(chunk)
            total += len(chunk)
            if total > max_bytes:  # it grew while being read
                raise _too_large(source, f"over {max_bytes:,} bytes", max_bytes)
        return b"".join(chunks)
    except OSError as exc:
        raise MapError(source, 0, f"cannot read the map: {exc.strerror or exc}") from exc
    finally:
        os.close(descriptor)


def _too_large(source: str, size: str, max_bytes: int) -> MapError:
    return MapError(source, 0, f"the file is {size}, more than the cap of {max_bytes:,} bytes "
                               "for a map; set CYBORG_MAP_MAX_BYTES to raise it")


# ---------------------------------------------------------------------- the grid
class DrawnMap(Protocol):
    """What the grid caps look at in a map (an :class:`~cyborg.nav.arnl_map.ArnlMap`)."""

    @property
    def source(self) -> str:
        """Where the map comes from, to name it in errors."""

    @property
    def lines(self) -> np.ndarray:
        """The walls, an (N, 4) array of ``x1 y1 x2 y2`` in metres."""

    @property
    def objects(self) -> list[MapObject]:
        """The map's objects; its forbidden lines and areas and simulator boxes are drawn."""

    def bounds(self) -> tuple[float, float, float, float]:
        """``(min_x, min_y, max_x, max_y)`` of everything in the map, in metres."""


def grid_shape(bounds: tuple[float, float, float, float], resolution: float,
               margin: float = GRID_MARGIN) -> tuple[int, int]:
    """``(rows, columns)`` of a grid over ``bounds`` (metres) plus ``margin`` on every side."""
    min_x, min_y, max_x, max_y = bounds
    origin_x, origin_y = min_x - margin, min_y - margin
    columns = math.ceil((max_x - origin_x + margin) / resolution) + 1
    rows = math.ceil((max_y - origin_y + margin) / resolution) + 1
    return rows, columns


def check_grid(arnl_map: DrawnMap, resolution: float = DEFAULT_RESOLUTION,
               margin: float = GRID_MARGIN, limits: MapLimits | None = None) -> None:
    """Raise MapError (naming the map) if a grid of ``arnl_map`` would cost too much.

    A grid at ``resolution`` (metres per cell), with ``margin`` metres around the map's extent,
    must stay within the cell cap of ``limits`` (default: :func:`map_limits`), and drawing its
    walls, forbidden lines and areas within the drawing cap.

    Runs before anything is allocated: on loading, at the default resolution, and again by
    :meth:`cyborg.nav.grid.MapGrid.from_map` at the resolution asked for.
    """
    limits = limits or map_limits()
    bounds = arnl_map.bounds()
    if not all(math.isfinite(value) for value in bounds):
        raise MapError(arnl_map.source, 0, f"the map's extent is not finite ({bounds})")
    rows, columns = grid_shape(bounds, resolution, margin)
    min_x, min_y, max_x, max_y = bounds
    if rows * columns > limits.max_cells:
        raise MapError(arnl_map.source, 0, (
            f"the map spans {max_x - min_x + 2 * margin:.1f} m x "
            f"{max_y - min_y + 2 * margin:.1f} m (its extent and a {margin:g} m margin): "
            f"{rows * columns:,} cells at {resolution:g} m, more than the cap of "
            f"{limits.max_cells:,} cells (about 50 bytes each in the simulator); set "
            "CYBORG_MAP_MAX_CELLS to raise it"))
    work = drawing_work(arnl_map, resolution)
    cap = DRAWING_FACTOR * limits.max_cells
    if work > cap:
        raise MapError(arnl_map.source, 0, (
            f"drawing its walls, forbidden lines and areas would visit {work:,} cells at "
            f"{resolution:g} m, more than {DRAWING_FACTOR} times the cell cap ({cap:,}); set "
            "CYBORG_MAP_MAX_CELLS to raise it"))


def segment_samples(segments: np.ndarray, resolution: float) -> np.ndarray:
    """How many points :meth:`MapGrid.mark_segments` samples along each ``x1 y1 x2 y2`` row."""
    lengths = np.hypot(segments[:, 2] - segments[:, 0], segments[:, 3] - segments[:, 1])
    counts: np.ndarray = np.maximum(2, np.ceil(lengths / (resolution / 3)).astype(np.int64) + 1)
    return counts


def drawing_work(arnl_map: DrawnMap, resolution: float) -> int:
    """Cells and samples visited drawing the map's lines and areas at ``resolution``.

    It is an upper bound: every area counts its bounding box and its outline, simulator boxes
    included.
    """
    work = int(segment_samples(arnl_map.lines, resolution).sum()) if len(arnl_map.lines) else 0
    for item in arnl_map.objects:
        corners = item.corners()
        if corners is None or not (item.is_forbidden_line or item.is_forbidden_area
                                   or item.is_sim_obstacle):
            continue
        outline = np.hstack([corners, np.roll(corners, -1, axis=0)])
        work += int(segment_samples(outline, resolution).sum())
        if len(corners) == 4:
            width, height = corners.max(axis=0) - corners.min(axis=0)
            work += (int(width / resolution) + 2) * (int(height / resolution) + 2)
    return work
