"""`cyborg bt run` in a real terminal (tmux): a node's prints, warnings and errors each start a
row of their own (an error in one line, no traceback), and the live status line is drawn below
them, never with them on one row."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

from tests.builders import N, project_json, tree_json

CHATTY = """
import logging
from cyborg.bt import Action, Status, register

log = logging.getLogger("cyborg.robot")

@register("Chatty")
class Chatty(Action):
    ticks = 0
    def tick(self) -> Status:
        Chatty.ticks += 1
        if Chatty.ticks % 5 == 0:
            print(f"said hello {Chatty.ticks}")
            log.warning("the way is blocked %d", Chatty.ticks)
        if Chatty.ticks == 33:
            raise ValueError("the sensor is unplugged")
        return Status.RUNNING
"""


def test_prints_and_warnings_never_share_a_row_with_the_status_line(tmp_path: Path) -> None:
    (tmp_path / "chatty_nodes.py").write_text(CHATTY)
    tree = tmp_path / "tree.json"
    tree.write_text(project_json([tree_json(
        N("Sequence", N("Chatty", id="c", title="MoveTo room1"), id="s"), title="Patrol")]))
    socket = f"cyborg-test-{os.getpid()}"
    path = os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])
    command = (f"cd {tmp_path} && PYTHONPATH={path} {sys.executable} -m cyborg bt run {tree} "
               "--nodes chatty_nodes --ticks 40 --rate 20; echo EXITED $?; sleep 60")
    tmux = ["tmux", "-L", socket]
    subprocess.run([*tmux, "new-session", "-d", "-x", "100", "-y", "50", command], check=True)
    try:
        screen = ""
        deadline = time.monotonic() + 120
        while "EXITED" not in screen and time.monotonic() < deadline:
            time.sleep(0.5)
            screen = subprocess.run([*tmux, "capture-pane", "-p", "-J"],  # wrapped rows joined
                                    capture_output=True, text=True, check=True).stdout
    finally:
        subprocess.run([*tmux, "kill-server"], check=False)
    rows = [row.rstrip() for row in screen.splitlines() if row.strip()]
    assert "EXITED 0" in rows[-1], screen
    said = [row for row in rows if "said hello" in row]
    warned = [row for row in rows if "the way is blocked" in row]
    assert len(said) == 8 and len(warned) == 8, screen
    assert all(row.startswith("said hello") for row in said), screen
    assert all(row.startswith("WARNING cyborg.robot: the way is blocked") for row in warned), \
        screen
    status = [row for row in rows if row.startswith("tick ")]
    assert len(status) == 1 and "RUNNING  Patrol > Sequence > MoveTo room1" in status[0], screen
    for row in rows:
        assert not ("tick " in row and ("said" in row or "WARNING" in row)), screen
    assert rows.index(status[0]) > rows.index(warned[-1]), "the line stays below them"
    assert "Traceback" not in screen
    (error,) = [row for row in rows if "ValueError" in row]  # one line, however long
    assert error.startswith("ERROR cyborg.bt: node c (MoveTo room1, Chatty) raised in tick"), \
        screen
    assert "ValueError: the sensor is unplugged (at " in error
