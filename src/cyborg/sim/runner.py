"""Running a simulator against the wall clock: real time, ``speed`` times faster, or flat out.

:class:`SimulationLoop` steps a :class:`~cyborg.sim.simulator.Simulator` on a thread of its own.
With ``speed`` 1 simulated time follows the wall clock; with ``speed`` 200 a simulated minute
passes in 0.3 s; with ``speed`` 0 (or infinity) it runs as fast as the machine allows. Whoever
touches the simulator from another thread holds ``loop.lock``. After every sensor step the
``on_sensor`` callbacks run (on the loop's thread, lock held) — that is where a bus node
publishes.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable

from cyborg.sim.simulator import Simulator

log = logging.getLogger("cyborg.sim")


class SimulationLoop:
    def __init__(self, simulator: Simulator, speed: float = 1.0) -> None:
        if speed < 0 or math.isnan(speed):
            raise ValueError(f"speed must be positive (or 0 for as fast as possible), not {speed}")
        self.simulator = simulator
        self.speed = math.inf if speed == 0 else speed
        self.lock = threading.RLock()
        self.on_sensor: list[Callable[[Simulator], None]] = []
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.error: BaseException | None = None

    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name="cyborg-sim", daemon=True)
        self._thread.start()

    def stop(self, timeout: float = 5.0) -> None:
        self._stop.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout)

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def _run(self) -> None:
        simulator = self.simulator
        started_wall = time.monotonic()
        started_sim = simulator.time
        every = simulator.steps_per_sensor
        try:
            while not self._stop.is_set():
                with self.lock:
                    for _ in range(every):
                        simulator.step()
                    for callback in list(self.on_sensor):
                        callback(simulator)
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
