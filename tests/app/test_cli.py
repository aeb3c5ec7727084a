"""The `cyborg` command: bt validate/run/dot/json/nodes and up."""

from __future__ import annotations

import json
import os
import shlex
import signal
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from cyborg.app.cli import main
from tests.builders import N, project_json, tree_json
from tests.conftest import shared_dir
from tests.doc_commands import ROOT, doc_commands
from tests.running_system import interruptible

PATROL = shared_dir() / "trees" / "patrol_recharge.b3.json"
STOCK = shared_dir() / "trees" / "stock_nodes.tree.json"


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "tree.json"
    path.write_text(text)
    return path


def test_validate_ok(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bt", "validate", str(STOCK)]) == 0
    assert "ok (0 errors, 0 warnings)" in capsys.readouterr().out


def test_validate_reports_all_problems_and_fails(tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    spec = N("Sequence", N("Nope", id="n1"), N("Inverter", id="i1"),
             N("Wait", id="w1", milliseconds="soon"), id="s")
    path = _write(tmp_path, json.dumps(tree_json(spec), indent=2))
    assert main(["bt", "validate", str(path)]) == 1
    out = capsys.readouterr().out
    lines = [line for line in out.splitlines() if ": error: " in line]
    assert len(lines) == 3
    assert all(line.startswith(f"{path}:") for line in lines)
    assert "(id n1)" in out and "(id i1)" in out and "(id w1)" in out
    assert "invalid (3 errors" in out


def test_validate_json_output(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _write(tmp_path, '{"trees": [}')
    assert main(["bt", "validate", "--json", str(path)]) == 1
    (problem,) = json.loads(capsys.readouterr().out)
    assert problem["severity"] == "error" and problem["line"] == 1 and problem["column"] == 12


def _teleporting(tmp_path: Path) -> Path:
    """The patrol tree with MoveTo renamed to a node nobody implements."""
    return _write(tmp_path, PATROL.read_text().replace("MoveTo", "Teleport"))


def test_the_robot_nodes_are_known(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bt", "validate", str(PATROL)]) == 0
    assert main(["bt", "nodes"]) == 0
    out = capsys.readouterr().out
    for name in ("MoveTo", "CheckBattery", "Charge", "Dock", "Undock", "ClosestGoal",
                 "DistanceToGoal", "BlackboardCompare", "ObjectDetected", "ClosestObject",
                 "FaceObject", "ApproachObject", "Say"):
        assert f"\n{name} " in out or f"{name}  " in out, name
    assert "entry point cyborg" in out or "cyborg.robot" in out


def test_validate_unknown_custom_nodes_and_stubs(tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    path = _teleporting(tmp_path)
    assert main(["bt", "validate", str(path)]) == 1
    out = capsys.readouterr().out
    assert "unknown node name 'Teleport' (declared in custom_nodes" in out
    assert main(["bt", "validate", str(path), "--stub-missing", "success"]) == 0


def test_validate_with_user_node_module(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "robot_nodes.py").write_text(
        "from cyborg.bt import Action, Decorator, Status, register\n"
        "@register\nclass MoveTo(Action):\n"
        "    def __init__(self, location: str, radius: float = 0.5) -> None: ...\n"
        "    def tick(self) -> Status: return Status.SUCCESS\n"
        "@register\nclass CheckBattery(Decorator):\n"
        "    def __init__(self, threshold: float) -> None: ...\n"
        "    def tick(self) -> Status: return Status.FAILURE\n"
        "@register\nclass Charge(Action):\n"
        "    def __init__(self, target: float) -> None: ...\n"
        "    def tick(self) -> Status: return Status.SUCCESS\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert main(["bt", "validate", str(PATROL), "--nodes", "robot_nodes"]) == 0
    assert main(["bt", "nodes", "--nodes", "robot_nodes"]) == 0
    out = capsys.readouterr().out
    assert "MoveTo" in out and "{location, radius=0.5}" in out


def test_bad_node_module_is_a_one_line_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "broken_nodes.py").write_text("raise ValueError('oops in module')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert main(["bt", "validate", str(STOCK), "--nodes", "no_such_module"]) == 1
    err = capsys.readouterr().err
    assert "cannot import node module 'no_such_module': ModuleNotFoundError" in err
    assert err.rstrip().endswith("(--nodes)")
    assert main(["bt", "run", str(STOCK), "--nodes", "broken_nodes"]) == 1
    err = capsys.readouterr().err
    assert "cannot import node module 'broken_nodes': ValueError: oops in module (--nodes)" in err
    assert "Traceback" not in err


def test_run_shows_status_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = N("MemSequence", N("Wait", id="w", title="Pause", milliseconds=300),
             N("Succeeder", id="s"), id="m")
    path = _write(tmp_path, project_json([tree_json(spec, title="Little")]))
    assert main(["bt", "run", str(path), "--fast", "--until-done"]) == 0
    out = capsys.readouterr().out
    assert "tick      1  RUNNING  Little > MemSequence > Pause" in out
    assert "tick      4  SUCCESS  -" in out
    assert "done after 4 ticks; last root status SUCCESS" in out


def test_run_by_tree_title_and_ticks(tmp_path: Path,
                                     capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["bt", "run", str(_teleporting(tmp_path)), "--tree", "Recharge tree",
                 "--stub-missing", "running", "--ticks", "3", "--rate", "50"])
    assert code == 0
    out = capsys.readouterr().out
    assert "running 'Recharge tree'" in out
    assert "Recharge tree > MemSequence > Teleport Dock" in out
    assert "done after 3 ticks" in out


def test_run_rejects_bad_file_and_options(tmp_path: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bt", "run", str(tmp_path / "none.json")]) == 1
    assert "cannot read the file" in capsys.readouterr().err
    assert main(["bt", "run", str(STOCK), "--rate", "0"]) == 2
    assert main(["bt", "run", str(STOCK), "--ticks", "0"]) == 2
    with pytest.raises(SystemExit):
        main(["bt", "run", str(STOCK), "--stub-missing", "maybe"])


def test_dot_and_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bt", "dot", str(STOCK)]) == 0
    assert capsys.readouterr().out.startswith('digraph "Stock nodes" {')
    out = tmp_path / "tree.json"
    assert main(["bt", "json", str(STOCK), "-o", str(out)]) == 0
    assert json.loads(out.read_text())["schema"] == "cyborg.bt.structure/1"


def _cyborg(*args: str) -> subprocess.Popen[str]:
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    return subprocess.Popen([sys.executable, "-m", "cyborg", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env,
                            preexec_fn=interruptible)




def test_ctrl_c_stops_cleanly_and_halts() -> None:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    process = _cyborg("up", "--listen", f"tcp/127.0.0.1:{port}", "--monitor-port", "0")
    assert process.stdout is not None
    first = process.stdout.readline()
    assert first.startswith("cyborg up: bus router at")
    hint = process.stdout.readline()  # not the default router: how other shells join it
    assert f"export CYBORG_CONNECT=tcp/127.0.0.1:{port}" in hint, hint
    while "MoveTo" not in process.stdout.readline():  # the robot is on its way
        pass
    process.send_signal(signal.SIGINT)
    _out, err = process.communicate(timeout=30)
    assert process.returncode == 130, err
    assert "cyborg up: stopped" in err
    assert "Traceback" not in err


def test_run_of_a_tree_that_needs_a_robot_stops_before_ticking(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bt", "run", str(PATROL), "--tree", "Patrol tree", "--ticks", "3"]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, "one clear line, no traceback"
    assert lines[0].startswith(f"{PATROL}: 4 nodes (MoveTo) need a robot")
    for way in ("cyborg up", "cyborg bt serve", "--stub-missing"):
        assert way in lines[0]
    assert "tick" not in captured.out, "nothing was ticked"
    assert main(["bt", "run", str(PATROL), "--ticks", "3"]) == 2
    assert "7 nodes (Charge, CheckBattery, MoveTo) need a robot" in capsys.readouterr().err


def test_stub_missing_stands_in_for_nodes_without_a_robot(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bt", "run", str(PATROL), "--tree", "Patrol tree", "--fast", "--ticks", "3",
                 "--stub-missing", "success"]) == 0
    out = capsys.readouterr().out
    assert "tick      1  RUNNING  Patrol tree > Repeat -1x > MemSequence > Wait 2000ms" in out


def test_a_run_whose_root_ends_in_error_fails(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    path = _write(tmp_path, project_json([tree_json(N("Sequence", N("Error", id="e"),
                                                      id="s"))]))
    assert main(["bt", "run", str(path), "--fast", "--ticks", "2"]) == 1
    assert "last root status ERROR" in capsys.readouterr().out


def test_the_readme_bt_commands_work_as_written(capsys: pytest.CaptureFixture[str]) -> None:
    shown = "../shared/trees/patrol_recharge.b3.json"
    commands = [command for command in doc_commands("cyborg", documents=(ROOT / "README.md",))
                if command.text.startswith("cyborg bt ") and shown in command.text
                and not command.text.startswith("cyborg bt serve")]  # serves until stopped
    assert len(commands) >= 4
    for command in commands:
        words = shlex.split(command.text.split("|")[0])  # the part before a pipe
        args = [str(PATROL) if word == shown else word for word in words[1:]]
        if args[1] == "run":
            args.append("--fast")  # the same ticks on simulated time
        assert main(args) == 0, f"{command.where}: {command.text}"
    assert "Traceback" not in capsys.readouterr().err


def test_up_refuses_a_tree_whose_goals_are_not_on_the_map() -> None:
    """The shared patrol drives to AMROffice.map's rooms; on the default campus map its MoveTos
    could never arrive: cyborg up names each (tree, node, id, goal), the map and its goals, and
    stops everything, rather than warn once per MoveTo while it runs. With its map it runs."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    common = ["up", "--tree", str(PATROL), "--listen", f"tcp/127.0.0.1:{port}",
              "--no-monitor", "--no-detector"]
    refused = subprocess.run([sys.executable, "-m", "cyborg", *common], capture_output=True,
                             text=True, timeout=60)
    assert refused.returncode == 1, refused.stderr
    assert "Traceback" not in refused.stderr
    lines = [line for line in refused.stderr.splitlines() if "cyborg.robot" not in line]
    assert lines[0].startswith("cyborg: error: patrol_recharge.b3.json: ")
    assert "MoveTos drive to goals not on campus.map (its goals: Charger," in lines[0]
    assert lines[0].endswith("give the tree's map with --map:")
    assert any(line.startswith("  tree 'Root tree', node 'MoveTo room1' (id ")
               and line.endswith("no goal 'room1'") for line in lines[1:]), lines
    amr = shared_dir() / "maps" / "AMROffice.map"
    runs = subprocess.run([sys.executable, "-m", "cyborg", *common, "--map", str(amr),
                           "--duration", "3"], capture_output=True, text=True, timeout=60)
    assert runs.returncode == 0, runs.stderr
    assert "no goal" not in runs.stderr
