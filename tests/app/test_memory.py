"""The `cyborg` process tunes glibc's malloc (cyborg.app.memory) unless told otherwise: few
arenas, and large buffers kept for reuse by a recorder."""

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


FAULTS = """
import resource, sys
from cyborg.app.memory import keep_large_buffers
if sys.argv[1] == "keep":
    assert keep_large_buffers()
def faults() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt
def frame() -> None:  # a frame's payload, chunk and record: filled together, then freed
    payload, chunk, record = bytearray(8_000_000), bytearray(8_000_000), bytearray(8_000_000)
for _ in range(3):  # let glibc's own thresholds adapt first, as they do in a long recording
    frame()
before = faults()
for _ in range(20):
    frame()
print(faults() - before)
"""


def test_large_buffers_are_reused_instead_of_faulted_in_again_for_each_frame() -> None:
    def faults(mode: str) -> int:
        env = {key: value for key, value in os.environ.items()
               if not key.startswith("MALLOC_")}
        done = subprocess.run([sys.executable, "-c", FAULTS, mode], env=env,
                              capture_output=True, text=True, check=True)
        return int(done.stdout)
    pages = 20 * 3 * 8_000_000 // 4096
    assert faults("default") > pages // 2  # fresh pages for every buffer
    assert faults("keep") < pages // 20  # the same pages again


def test_an_explicit_malloc_threshold_in_the_environment_wins() -> None:
    check = "from cyborg.app.memory import keep_large_buffers; print(keep_large_buffers())"
    told = subprocess.run([sys.executable, "-c", check],
                          env={**os.environ, "MALLOC_TRIM_THRESHOLD_": "1000000"},
                          capture_output=True, text=True, check=True)
    assert told.stdout.strip() == "False"
