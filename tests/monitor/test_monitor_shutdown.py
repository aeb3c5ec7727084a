"""A monitor that stops, or a process that exits, while a robot's map is still being laid out
says nothing of it: no "cannot schedule new futures after shutdown" traceback, no error logged
(the map build is given up, the periodic work ends; cyborg.monitor.off_loop)."""

from __future__ import annotations

import logging
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from cyborg.bus import BusConfig, Context, Node
from cyborg.bus.msgs.cyborg_msgs.msg import MapGeometry
from cyborg.monitor import Monitor
from tests.monitor.robot_messages import FakeMapRobot, map_geometry, pose
from tests.running_system import wait_until

pytestmark = pytest.mark.heavy

ROOT = Path(__file__).resolve().parents[2]
BIG_POINTS = 1_900_000
"""Points of a map that takes the monitor a while to lay out (the limit is 2,000,000)."""


def _big_map() -> MapGeometry:
    points = np.random.default_rng(7).uniform(-50.0, 50.0, 2 * BIG_POINTS).astype(np.float32)
    return map_geometry(points=points)


def test_a_monitor_stopped_while_a_map_is_laid_out_logs_nothing(
        caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.WARNING)
    with Context(BusConfig.isolated()) as context:
        monitor = Monitor(Node("monitor", "/cyborg", context=context), port=0)
        fake = FakeMapRobot(Node("arnl", "/robot1", context=context))
        monitor.start()
        hub = monitor.hub.robot_hub
        try:
            def followed() -> bool:
                fake.pose.publish(pose())
                return "/robot1" in hub.robots

            wait_until(followed, 20.0, "the robot followed")
            fake.map.publish(_big_map())
            wait_until(lambda: hub.robots["/robot1"].building, 20.0, "a map build under way")
        finally:
            monitor.stop()
        assert not hub._tasks, "the build was given up"
    errors = [record.getMessage() for record in caplog.records if record.levelno >= logging.ERROR]
    assert errors == []


def test_a_process_that_exits_while_a_map_is_laid_out_prints_no_traceback(
        tmp_path: Path) -> None:
    script = tmp_path / "exit_early.py"
    script.write_text(textwrap.dedent(f"""
        import sys, time
        sys.path[:0] = [{str(ROOT / "src")!r}, {str(ROOT)!r}]
        from cyborg.bus import BusConfig, Context, Node
        from cyborg.monitor import Monitor
        from tests.monitor.robot_messages import FakeMapRobot, pose
        from tests.monitor.test_monitor_shutdown import _big_map
        from tests.running_system import wait_until

        context = Context(BusConfig.isolated())
        monitor = Monitor(Node("monitor", "/cyborg", context=context), port=0)
        fake = FakeMapRobot(Node("arnl", "/robot1", context=context))
        monitor.start()
        hub = monitor.hub.robot_hub
        def followed():
            fake.pose.publish(pose())
            return "/robot1" in hub.robots
        wait_until(followed, 20.0)
        fake.map.publish(_big_map())
        wait_until(lambda: hub.robots["/robot1"].building, 20.0)
        print("exiting with the map still being laid out", flush=True)
    """))  # the monitor is left running: its thread outlives the executors as Python exits
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          timeout=120, cwd=tmp_path, check=False)
    assert "exiting with the map still being laid out" in done.stdout, done.stderr
    assert "cannot schedule new futures" not in done.stderr, done.stderr
    assert "Traceback" not in done.stderr, done.stderr
