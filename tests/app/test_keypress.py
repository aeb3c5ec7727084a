"""Single keys from a terminal: a bound key runs its action, the terminal is left as found."""

from __future__ import annotations

import io
import os
import pty
import termios
import time

from cyborg.app.keypress import Keys


def test_a_bound_key_runs_its_action_and_the_terminal_is_restored() -> None:
    controller, terminal = pty.openpty()
    stream = os.fdopen(terminal, "r")
    try:
        before = termios.tcgetattr(terminal)
        pressed: list[str] = []
        with Keys(stream, {"p": lambda: pressed.append("p")}) as keys:
            assert keys.active
            assert termios.tcgetattr(terminal) != before  # cbreak: no line editing, no echo
            os.write(controller, b"xP")
            deadline = time.monotonic() + 10
            while not pressed and time.monotonic() < deadline:
                keys.wait(0.1)
        assert pressed == ["p"]  # "x" is bound to nothing; "P" counts as "p"
        assert termios.tcgetattr(terminal) == before
    finally:
        stream.close()
        os.close(controller)


def test_without_a_terminal_keys_are_not_read() -> None:
    pressed: list[str] = []
    piped = io.StringIO("p")
    with Keys(piped, {"p": lambda: pressed.append("p")}) as keys:
        assert not keys.active
        keys.wait(0.01)
    assert pressed == [] and piped.read() == "p"  # the input is left to whoever reads it
