"""``cyborg nav`` and ``cyborg sim`` from the command line."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from cyborg.app.cli import main
from tests.ports import free_port


def test_nav_goals_lists_names_kinds_and_headings(shared: Path,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["nav", "goals", str(shared / "maps" / "AMROffice.map")]) == 0
    out = capsys.readouterr().out
    assert "Far Away" in out and "-91.9°" in out and out.count("\n") == 7


def test_nav_plan_prints_the_length_or_why_not(shared: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    columbia = str(shared / "maps" / "columbia.map")
    assert main(["nav", "plan", columbia, "Goal 1", "Hallway 2", "--waypoints"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first.endswith("ms)") and 45 < float(first.split()[0]) < 60
    assert main(["nav", "plan", columbia, "--", "-0.182,0.176", "Impossible Goal"]) == 1
    assert "NO_VALID_PATH" in capsys.readouterr().out
    assert main(["nav", "plan", columbia, "Goal 1", "kitchen"]) == 1
    assert "no goal named 'kitchen'" in capsys.readouterr().err


def test_bad_map_file_is_reported_with_its_line(tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.map"
    bad.write_text("2D-Map\nDATA\n1 2\n3 4 5\n")
    assert main(["nav", "goals", str(bad)]) == 1
    assert f"{bad}:4: DATA: expected 2 numbers, found '3 4 5'" in capsys.readouterr().err


@pytest.mark.heavy
def test_cyborg_sim_runs_for_a_simulated_duration(shared: Path, tmp_path: Path) -> None:
    port = free_port()
    done = subprocess.run(
        [sys.executable, "-m", "cyborg", "sim", "--map", str(shared / "maps" / "AMROffice.map"),
         "--speed", "0", "--duration", "30", "--start", "Dock",
         "--listen", f"tcp/127.0.0.1:{port}"],
        capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "AMROffice.map at full speed, namespace /cyborg, router at" in done.stdout


@pytest.mark.heavy
def test_cyborg_sim_runs_several_robots(shared: Path) -> None:
    port = free_port()
    done = subprocess.run(
        [sys.executable, "-m", "cyborg", "sim", "--map", str(shared / "maps" / "AMROffice.map"),
         "--speed", "0", "--duration", "10", "--robots", "3", "--namespace", "/",
         "--listen", f"tcp/127.0.0.1:{port}"],
        capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert ("AMROffice.map at full speed, 3 robots under /robot1, /robot2, /robot3, router at"
            in done.stdout)
    refused = subprocess.run(
        [sys.executable, "-m", "cyborg", "sim", "--map", str(shared / "maps" / "AMROffice.map"),
         "--robots", "17", "--listen", f"tcp/127.0.0.1:{port}"],
        capture_output=True, text=True, timeout=120)
    assert refused.returncode != 0
    assert "parameter `robots` must be a whole number from 1 to 16, not 17" in refused.stderr
