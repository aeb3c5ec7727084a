"""The `cyborg` process limits glibc's malloc arenas (cyborg.app.memory) unless told otherwise."""

from __future__ import annotations

import os
import subprocess
import sys

CHECK = "from cyborg.app.memory import limit_malloc_arenas; print(limit_malloc_arenas())"


def test_arenas_are_limited_on_glibc_and_an_explicit_setting_wins() -> None:
    env = {key: value for key, value in os.environ.items() if key != "MALLOC_ARENA_MAX"}
    limited = subprocess.run([sys.executable, "-c", CHECK], env=env, capture_output=True,
                             text=True, check=True)
    assert limited.stdout.strip() == "True"
    told = subprocess.run([sys.executable, "-c", CHECK], env={**env, "MALLOC_ARENA_MAX": "4"},
                          capture_output=True, text=True, check=True)
    assert told.stdout.strip() == "False"
