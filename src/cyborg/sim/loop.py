"""Running a simulator against the wall clock: real time, ``speed`` times faster, or flat out.

:class:`SimulationLoop` steps a :class:`~cyborg.sim.simulator.Simulator` on a thread of its own.
With ``speed`` 1 simulated time follows the wall clock; with ``speed`` 200 a simulated minute
passes in 0.3 s; with ``speed`` 0 (or infinity) it runs as fast as the machine allows. Whoever
touches the simulator from another thread holds ``loop.lock``. After every sensor step the
``on_sensor`` callbacks run (on the loop's thread, lock held) — that is where a bus node
publishes.

A :class:`PacedLoop` steps anything :class:`Stepped`: one simulator, or a fleet of them on one map
(:class:`cyborg.sim.fleet.Fleet`, whose robots each have a :class:`RobotLoop` of their own).
:class:`RobotLoop` is what a robot's bus node needs of the loop that steps its simulator.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable
from typing import Generic, Protocol, TypeVar

from cyborg.sim.simulator import Simulator

log = logging.getLogger("cyborg.sim")

REAL_TIME = 1.0
"""The speed at which simulated time follows the wall clock: the default."""


class SimulationLock:
    """A re-entrant lock that the simulation thread hands over to anyone waiting for it.

    Running flat out, the simulation thread would take its lock back right after releasing
    it, and a thread that wants to start a goal could wait for seconds of simulated time.
    Whoever enters this lock is counted; between steps the simulation lets them all go first.
    """

    def __init__(self) -> None:
        self._lock = threading.RLock()
        self._count = threading.Lock()
        self.waiting = 0

    def __enter__(self) -> SimulationLock:
        with self._count:
            self.waiting += 1
        self._lock.acquire()
        with self._count:
            self.waiting -= 1
        return self

    def __exit__(self, *exc: object) -> None:
        self._lock.release()

    def acquire_for_steps(self) -> None:
        """Take the lock for the simulation thread (not counted as waiting)."""
        self._lock.acquire()

    def release_after_steps(self, patience: float = 0.005) -> None:
        """Release, and let waiting threads in first (for at most ``patience`` seconds)."""
        self._lock.release()
        if self.waiting:
            deadline = time.monotonic() + patience
            while self.waiting and time.monotonic() < deadline:
                time.sleep(0)


class Stepped(Protocol):
    """What a loop can step: a simulator, or a fleet of them.

    Simulated ``time`` (s) is advanced one physics step by ``step()``, with a sensor step every
    ``steps_per_sensor`` physics steps.
    """

    @property
    def time(self) -> float:
        """Simulated seconds since the start."""

    @property
    def steps_per_sensor(self) -> int:
        """Physics steps per sensor step."""

    def step(self) -> None:
        """Advance one physics step."""


World = TypeVar("World", bound=Stepped)


class RobotLoop(Protocol):
    """What a simulated robot's bus node needs of the loop that steps it.

    Its ``simulator``, the ``lock`` to hold while touching it, the ``on_sensor`` callbacks run
    after each sensor step (on the loop's thread, lock held), the ``error`` that stopped the
    loop, whether it is ``running``, and ``stop``. A :class:`SimulationLoop` of one simulator
    is one; so is each robot's share of a fleet's loop.
    """

    @property
    def simulator(self) -> Simulator:
        """The robot's simulator."""

    @property
    def lock(self) -> SimulationLock:
        """Held by whoever touches the simulator from another thread."""

    @property
    def on_sensor(self) -> list[Callable[[Simulator], None]]:
        """Run after each sensor step, on the loop's thread, lock held."""

    @property
    def error(self) -> BaseException | None:
        """What stopped the loop, if it failed."""

    @property
    def running(self) -> bool:
        """Whether the simulation steps."""

    def stop(self, timeout: float = 5.0) -> None:
        """Stop stepping the robot."""


class PacedLoop(Generic[World]):
    """Steps ``simulator`` (one, or a fleet) on a thread of its own at ``speed``.

    See the module doc. Whoever touches the simulator from another thread holds :attr:`lock`;
    the ``on_sensor`` callbacks run on the loop's thread, lock held, after each sensor step;
    :attr:`error` holds what stopped the loop if it failed.
    """

    def __init__(self, simulator: World, speed: float = REAL_TIME) -> None:
        self.simulator = simulator
        self.speed = speed
        self.lock = SimulationLock()
        self.on_sensor: list[Callable[[World], None]] = []
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.error: BaseException | None = None

    @property
    def speed(self) -> float:
        """Simulated seconds per wall-clock second; ``inf`` when running flat out."""
        return self._speed

    @speed.setter
    def speed(self, speed: float) -> None:
        """Set the pace; 0 (or infinity) means as fast as possible. Takes effect at once."""
        if speed < 0 or math.isnan(speed):
            raise ValueError(f"speed must be positive (or 0 for as fast as possible), not {speed}")
        self._speed = math.inf if speed == 0 else speed

    def start(self) -> None:
        """Start stepping on the loop's thread, ``cyborg-sim``."""
        self._thread = threading.Thread(target=self._run, name="cyborg-sim", daemon=True)
        self._thread.start()

    def stop(self, timeout: float = 5.0) -> None:
        """Stop after the current step; wait up to ``timeout`` seconds unless called by the loop."""
        self._stop.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout)

    @property
    def running(self) -> bool:
        """Whether the loop's thread is alive: started, and neither stopped nor failed."""
        return self._thread is not None and self._thread.is_alive()

    def _run(self) -> None:
        simulator = self.simulator
        started_wall = time.monotonic()
        started_sim = simulator.time
        every = simulator.steps_per_sensor
        try:
            while not self._stop.is_set():
                self.lock.acquire_for_steps()
                try:
                    for _ in range(every):
                        simulator.step()
                    for callback in list(self.on_sensor):
                        callback(simulator)
                finally:
                    self.lock.release_after_steps()
                if math.isfinite(self.speed):
                    ahead = (simulator.time - started_sim) / self.speed - (
                        time.monotonic() - started_wall)
                    if ahead > 0:
                        self._stop.wait(ahead)
                    elif ahead < -1.0:  # fell behind (a slow machine): do not try to catch up
                        started_wall = time.monotonic()
                        started_sim = simulator.time
        except BaseException as exc:  # reported, not swallowed: the owner checks .error
            self.error = exc
            log.exception("the simulation stopped")


class SimulationLoop(PacedLoop[Simulator]):
    """Steps one :class:`~cyborg.sim.simulator.Simulator`.

    It is a :class:`PacedLoop` and a :class:`RobotLoop` at once (see the module doc).
    """
