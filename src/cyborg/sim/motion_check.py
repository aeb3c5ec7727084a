"""Checking a speed command against where the robot's momentum will carry it.

A robot cannot stop or turn at once: with 0.5 m/s² of braking, a robot at 1 m/s still rolls a
metre. A command that looks right for the path (turn in place towards a new goal) can therefore
sweep the body into a wall when it is given while the robot still moves — for instance right
after a goal was replaced by another one. Before a command is sent, :func:`stopping_gap` plays
it forward: the command for one control period, then braking to a standstill, both within the
drive's acceleration limits. Along that motion it measures the smallest gap between the body
(its covering circles) and what the robot knows about: the map's walls (a clearance grid) and
the laser's latest returns. :func:`safest_command` keeps the wanted command when that gap stays
open, and otherwise falls back to gentler turns, a slow creep or braking straight — the idea
behind ARNL's dynamic-window velocity choice, reduced to the few candidates a path follower
needs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache

import numpy as np
from numba import njit

from cyborg.nav.footprint import Footprint
from cyborg.sim.robot import arc_step, body_gap


@dataclass(frozen=True)
class Motion:
    """How the robot moves now, how fast it can change that, and the step of its drive.

    ``speed`` (m/s) and ``turn_rate`` (rad/s) are the motion now, ``acceleration`` (m/s²) and
    ``turn_acceleration`` (rad/s²) its limits, ``step`` (s) the period at which the drive
    applies changes.
    """

    speed: float
    turn_rate: float
    acceleration: float
    turn_acceleration: float
    step: float = 0.02


@dataclass(frozen=True)
class Surroundings:
    """What the robot knows of the world near it: a wall clearance grid and laser returns.

    ``origin`` (m, the lower-left corner of cell (0, 0)) and ``resolution`` (m per cell) place
    the grid as a :class:`~cyborg.nav.grid.MapGrid` is placed.
    """

    clearance: np.ndarray  # metres from each cell centre to the nearest wall
    origin: tuple[float, float]
    resolution: float
    hits: np.ndarray  # (N, 2) map points of the latest scan


MARGIN = 0.0
"""Gap (m) a command must keep along its motion to count as safe. Zero suits the simulator,
whose body and walls are exactly the ones checked here; doors the planner squeezes through
(at the inscribed radius) leave no more. A real base would want its sensors' error here."""

CREEP = 0.1
"""Speed (m/s) at which a robot that cannot turn where it stands backs off or edges forward."""


def stopping_gap(x: float, y: float, theta: float, motion: Motion, command: tuple[float, float],
                 period: float, footprint: Footprint, around: Surroundings,
                 enough: float = math.inf) -> float:
    """The smallest gap (m) between the body and the surroundings along a command and braking.

    The robot at ``(x, y, theta)`` follows ``command`` (m/s, rad/s) for ``period`` seconds and
    then brakes to a standstill; the gap is negative when the body overlaps something.

    Poses whose gap is certainly at least ``enough`` are not looked at: then the result is
    exact only when it is below ``enough``; above, it only says "at least ``enough``".
    """
    offsets, radius = footprint.circles()
    hits = np.ascontiguousarray(around.hits, dtype=np.float64).reshape(-1, 2)
    return float(_stopping_gap(
        x, y, theta, motion.speed, motion.turn_rate, command[0], command[1],
        motion.acceleration, motion.turn_acceleration, motion.step, period, enough,
        offsets, radius, around.clearance, around.origin[0], around.origin[1],
        around.resolution, hits))


def safest_command(x: float, y: float, theta: float, motion: Motion,
                   wanted: tuple[float, float], period: float, footprint: Footprint,
                   around: Surroundings) -> tuple[float, float]:
    """The command to send (m/s, rad/s): ``wanted`` if it is safe, else the safest fallback.

    ``wanted`` is safe when its motion keeps :data:`MARGIN` (or, where the robot is closer than
    that already, does not get closer); otherwise the first safe of: the same speed with half
    and a quarter of the turn; no speed with half and a quarter of the turn; when the wanted
    turn was on the spot, :data:`CREEP` forwards, then backwards, on a tight arc (full, then
    half turn), then straight; otherwise, where the robot is closer than :data:`MARGIN`
    already (wedged beside another robot), :data:`CREEP` straight forwards, then backwards;
    and at last braking straight. When none is safe, the one keeping most room (the gentler
    one of equals).

    Checked again every control period, this keeps the robot clear by induction: once a safe
    command was chosen, braking after it was found clear, so next period braking still is.
    One compiled call weighs them all (:func:`_safest`), as :func:`stopping_gap` would one by
    one.
    """
    offsets, radius = _circles(footprint)
    hits = np.ascontiguousarray(around.hits, dtype=np.float64).reshape(-1, 2)
    speed, turn = _safest(
        x, y, theta, motion.speed, motion.turn_rate, wanted[0], wanted[1], motion.acceleration,
        motion.turn_acceleration, motion.step, period, offsets, radius, around.clearance,
        around.origin[0], around.origin[1], around.resolution, hits, MARGIN, CREEP)
    return (wanted[0], wanted[1]) if (speed, turn) == wanted else (float(speed), float(turn))


@cache
def _circles(footprint: Footprint) -> tuple[np.ndarray, float]:
    """The footprint's covering circles (kept: the same every control period)."""
    offsets, radius = footprint.circles()
    offsets.setflags(write=False)
    return offsets, radius


def warm_up() -> None:
    """Compile (or load from numba's cache) the check's kernel now.

    The first compilation takes seconds, which would otherwise fall on the robot's first move.
    """
    around = Surroundings(np.ones((4, 4), np.float32), (0.0, 0.0), 1.0, np.zeros((1, 2)))
    stopping_gap(2.0, 2.0, 0.0, Motion(0.0, 0.0, 1.0, 1.0), (0.0, 0.0), 0.1,
                 Footprint(length=0.2, width=0.1), around)
    safest_command(2.0, 2.0, 0.0, Motion(0.0, 0.0, 1.0, 1.0), (0.1, 0.1), 0.1,
                   Footprint(length=0.2, width=0.1), around)


@njit(cache=True)
def _limited(value: float, most: float) -> float:  # pragma: no cover - jit
    return max(-most, min(most, value))


@njit(cache=True)
def _near(hits: np.ndarray, x: float, y: float, v: float, w: float, cmd_v: float,
          cmd_w: float, accel: float, turn_accel: float, period: float, offsets: np.ndarray,
          radius: float) -> np.ndarray:  # pragma: no cover - jit
    """The returns the body may come near following ``cmd_v``/``cmd_w``, then braking.

    Only those matter: the stopping motion from ``(x, y)`` reaches no further; returns beyond
    are more than half a metre clear of the body wherever it goes.
    """
    stop = (abs(v) + abs(cmd_v)) * (period + (abs(v) + abs(cmd_v)) / accel)
    turn = (abs(w) + abs(cmd_w)) * (period + (abs(w) + abs(cmd_w)) / turn_accel)
    farthest = np.abs(offsets).max()
    around = stop + turn * farthest + farthest + radius + 0.5
    count = 0
    near = np.empty_like(hits)
    for i in range(hits.shape[0]):
        if abs(hits[i, 0] - x) < around and abs(hits[i, 1] - y) < around:
            near[count] = hits[i]
            count += 1
    return near[:count]


@njit(cache=True)
def _safest(x: float, y: float, theta: float, v: float, w: float, speed: float, turn: float,
            accel: float, turn_accel: float, dt: float, period: float, offsets: np.ndarray,
            radius: float, clearance: np.ndarray, ox: float, oy: float, resolution: float,
            hits: np.ndarray, margin: float,
            creep: float) -> tuple[float, float]:  # pragma: no cover - jit
    """:func:`safest_command`'s choice, the candidates weighed in one call.

    The returns are sifted once, for the candidate that reaches furthest: a return further
    off is more than half a metre clear of the body for every candidate, so it changes no gap
    that decides (those below ``margin``, and below zero), and the choice is the one
    :func:`stopping_gap` gives candidate by candidate.
    """
    candidates = [(speed, turn), (speed, turn / 2), (speed, turn / 4), (0.0, turn / 2),
                  (0.0, turn / 4)]
    near = _near(hits, x, y, v, w, max(abs(speed), creep), abs(turn), accel, turn_accel,
                 period, offsets, radius)
    standing = body_gap(x, y, theta, offsets, radius, clearance, ox, oy, resolution, near)
    needed = min(margin, standing)
    if speed == 0.0 and turn != 0.0:  # a turn on the spot: or on a tight arc, or straight
        candidates += [(creep, turn), (creep, turn / 2), (-creep, turn), (-creep, turn / 2),
                       (creep, 0.0), (-creep, 0.0)]
    elif standing < margin:  # closer than it should be already: or out straight
        candidates += [(creep, 0.0), (-creep, 0.0)]
    candidates.append((0.0, 0.0))
    for cmd_v, cmd_w in candidates:  # each played only until it fails
        gap = _motion_gap(x, y, theta, v, w, cmd_v, cmd_w, accel, turn_accel, dt, period,
                          needed, offsets, radius, clearance, ox, oy, resolution, near,
                          needed)
        if gap >= needed:
            return cmd_v, cmd_w
    best, best_gap = candidates[0], -np.inf
    for cmd_v, cmd_w in candidates:  # none is safe: the one keeping most room, played out
        gap = _motion_gap(x, y, theta, v, w, cmd_v, cmd_w, accel, turn_accel, dt, period,
                          needed, offsets, radius, clearance, ox, oy, resolution, near,
                          -np.inf)
        if gap >= best_gap:
            best, best_gap = (cmd_v, cmd_w), gap
    return best


@njit(cache=True)
def _stopping_gap(x: float, y: float, theta: float, v: float, w: float, cmd_v: float,
                  cmd_w: float, accel: float, turn_accel: float, dt: float, period: float,
                  enough: float, offsets: np.ndarray, radius: float, clearance: np.ndarray,
                  ox: float, oy: float, resolution: float,
                  hits: np.ndarray) -> float:  # pragma: no cover - jit
    near = _near(hits, x, y, v, w, cmd_v, cmd_w, accel, turn_accel, period, offsets, radius)
    return _motion_gap(x, y, theta, v, w, cmd_v, cmd_w, accel, turn_accel, dt, period, enough,
                       offsets, radius, clearance, ox, oy, resolution, near, -np.inf)


@njit(cache=True)
def _motion_gap(x: float, y: float, theta: float, v: float, w: float, cmd_v: float,
                cmd_w: float, accel: float, turn_accel: float, dt: float, period: float,
                enough: float, offsets: np.ndarray, radius: float, clearance: np.ndarray,
                ox: float, oy: float, resolution: float, near: np.ndarray,
                fails: float) -> float:  # pragma: no cover - jit
    """:func:`stopping_gap` over returns already sifted to those near (``near``).

    Ends early, with a gap below ``fails``, at the first pose found closer than that.
    """
    farthest = np.abs(offsets).max()
    # the motion, integrated as the simulated drive does (its arc_step, body_gap). A body whose
    # gap was g can move g before touching, give or take a grid cell: poses are looked at only
    # once the way moved since the last look could have used up the room above ``enough``
    slack = 1.5 * resolution
    lowest = body_gap(x, y, theta, offsets, radius, clearance, ox, oy, resolution, near)
    looked, moved, t = lowest, 0.0, 0.0
    while t < 60.0:  # bounded: braking always ends
        target_v, target_w = (cmd_v, cmd_w) if t < period else (0.0, 0.0)
        v += _limited(target_v - v, accel * dt)
        w += _limited(target_w - w, turn_accel * dt)
        x, y, theta = arc_step(x, y, theta, v, w, dt)
        moved += (abs(v) + abs(w) * farthest) * dt
        t += dt
        if looked - moved - slack < enough:
            looked = body_gap(x, y, theta, offsets, radius, clearance, ox, oy, resolution, near)
            lowest, moved = min(lowest, looked), 0.0
            if lowest < fails:
                break
        if t >= period and v == 0.0 and w == 0.0:
            break
    return lowest
