"""Ctrl-C while a command starts: exit code 130 and no traceback, whenever it comes.

`cyborg sim` imports for seconds on a busy machine (numba's compiled code, Zenoh, the message
types) before it says "Ctrl-C stops". SIGINT is sent at several moments of that start-up:
right after given modules were imported (``-X importtime`` says when, on stderr), so the
interrupt lands in the imports that follow them, and once the simulator runs.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
from importlib.resources import files

import pytest

from tests.ports import free_port
from tests.running_system import interruptible

CAMPUS = str(files("cyborg.app").joinpath("data", "campus.map"))

MOMENTS = ["cyborg.app.memory", "cyborg.app.bus_options", "cyborg.bus", "cyborg.interfaces",
           "cyborg.nav", "cyborg.sim.robot", "Ctrl-C stops"]
"""After which import (or, the last, which line of output) SIGINT is sent. The first is the
first module ``main`` imports: before it, the interpreter starts and imports the entry point,
a few milliseconds that no program can cover. (The command modules ``main`` imports by
name are not timed by ``-X importtime``; the modules they import are. ``cyborg sim`` imports
only what it runs: neither the tree engine nor the other commands.)"""

START_LIMIT = 120.0
"""Seconds the start-up may take to reach a moment (minutes on a loaded machine)."""


@pytest.mark.parametrize("moment", MOMENTS)
def test_ctrl_c_during_start_up_exits_130_without_a_traceback(moment: str) -> None:
    command = [sys.executable, "-X", "importtime", "-m", "cyborg", "sim", "--map", CAMPUS,
               "--listen", f"tcp/127.0.0.1:{free_port()}"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               text=True, env=dict(os.environ, PYTHONUNBUFFERED="1"),
                               preexec_fn=interruptible)
    assert process.stdout is not None
    seen: list[str] = []
    watchdog = threading.Timer(START_LIMIT, process.kill)  # a moment never reached ends it
    watchdog.start()
    try:
        for line in process.stdout:  # import times and the command's own lines, as they come
            seen.append(line)
            imported = line.startswith("import time:") and line.split("|")[-1].strip() == moment
            if imported or (moment in line and not line.startswith("import time:")):
                break
        else:
            pytest.fail(f"the start-up never reached {moment!r}:\n{''.join(seen[-20:])}")
    finally:
        watchdog.cancel()
    process.send_signal(signal.SIGINT)
    rest, _ = process.communicate(timeout=60)
    output = "".join(seen) + rest
    assert process.returncode == 130, output[-3000:]
    assert "Traceback" not in output, output[-3000:]
    assert "KeyboardInterrupt" not in output, output[-3000:]
