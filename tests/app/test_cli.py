"""The `cyborg` command: bt validate/run/dot/json/nodes and up."""

from __future__ import annotations

import json
import os
import shlex
import signal
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from cyborg.app.cli import main
from cyborg.bt import default_registry
from tests.builders import N, project_json, tree_json
from tests.conftest import shared_dir
from tests.doc_commands import ROOT, doc_commands
from tests.ports import free_port
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


@pytest.fixture
def own_registered(monkeypatch: pytest.MonkeyPatch) -> None:
    """The test's nodes are registered in a copy of the decorator's registry, dropped after."""
    from cyborg.bt import registry as registry_module

    default_registry()  # the robot's nodes are in (an entry point), as in any command
    monkeypatch.setattr(registry_module, "_REGISTERED", registry_module._REGISTERED.copy())


def test_validate_with_user_node_module(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                        capsys: pytest.CaptureFixture[str],
                                        own_registered: None) -> None:
    (tmp_path / "robot_nodes.py").write_text(  # stand-ins for the robot's nodes, on purpose
        "from cyborg.bt import Action, Decorator, Status, register\n"
        "@register('MoveTo', override=True)\nclass MoveTo(Action):\n"
        "    def __init__(self, location: str, radius: float = 0.5) -> None: ...\n"
        "    def tick(self) -> Status: return Status.SUCCESS\n"
        "@register('CheckBattery', override=True)\nclass CheckBattery(Decorator):\n"
        "    def __init__(self, threshold: float) -> None: ...\n"
        "    def tick(self) -> Status: return Status.FAILURE\n"
        "@register('Charge', override=True)\nclass Charge(Action):\n"
        "    def __init__(self, target: float) -> None: ...\n"
        "    def tick(self) -> Status: return Status.SUCCESS\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert main(["bt", "validate", str(PATROL), "--nodes", "robot_nodes"]) == 0
    assert main(["bt", "nodes", "--nodes", "robot_nodes"]) == 0
    out = capsys.readouterr().out
    assert "MoveTo" in out and "{location, radius=0.5}" in out
    monkeypatch.delitem(sys.modules, "robot_nodes")


SAY_NODES = """  # a user's Say, as the README's example had it
from cyborg.bt import Action, Status, register

@register{how}
class Say(Action):
    def __init__(self, text: str = "hello") -> None:
        self.text = text
    def tick(self) -> Status:
        print(self.text)
        return Status.SUCCESS
"""


def test_a_users_node_named_as_a_robot_node_is_refused_naming_both_unless_it_overrides(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
        own_registered: None) -> None:
    (tmp_path / "my_nodes.py").write_text(SAY_NODES.format(how=""))
    monkeypatch.syspath_prepend(str(tmp_path))
    assert main(["bt", "nodes", "--nodes", "my_nodes"]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert "node name 'Say' is taken by cyborg.robot.say.Say (from cyborg.robot.say); " \
           "my_nodes.Say (from my_nodes) would replace it: register it with override=True" in err
    monkeypatch.delitem(sys.modules, "my_nodes", raising=False)
    (tmp_path / "my_nodes.py").write_text(SAY_NODES.format(how="('Say', override=True)"))
    assert main(["bt", "nodes", "--nodes", "my_nodes"]) == 0
    said = [line for line in capsys.readouterr().out.splitlines() if line.startswith("Say ")]
    assert len(said) == 1 and said[0].endswith("[my_nodes]"), said
    monkeypatch.delitem(sys.modules, "my_nodes")


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
    port = free_port()
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
    port = free_port()
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


HOME_NODES = """
from cyborg.bt import Action, Condition, Status, register
from cyborg.robot import robot_of

@register("AtHome?")
class AtHome(Condition):
    def tick(self) -> bool:                 # True/False mean SUCCESS/FAILURE
        pose = robot_of(self).pose
        return pose is not None and abs(pose.x) + abs(pose.y) < 1.0

@register("Broken")
class Broken(Action):
    def tick(self) -> Status:
        raise ValueError("the sensor is unplugged")
"""


def test_a_node_that_calls_robot_of_is_refused_before_the_first_tick_in_one_line(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
        caplog: pytest.LogCaptureFixture, own_registered: None) -> None:
    (tmp_path / "home_nodes.py").write_text(HOME_NODES)
    monkeypatch.syspath_prepend(str(tmp_path))
    path = _write(tmp_path, project_json([tree_json(
        N("Sequence", N("AtHome?", id="home"), N("Succeeder", id="s"), id="seq"),
        title="Home")]))
    assert main(["bt", "run", str(path), "--nodes", "home_nodes", "--ticks", "3"]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, captured.err
    assert lines[0].startswith(f"{path}: 1 node (AtHome?) need a robot"), lines[0]
    assert "tick" not in captured.out, "nothing was ticked"
    assert main(["bt", "run", str(path), "--nodes", "home_nodes", "--ticks", "2",
                 "--stub-missing", "success", "--fast"]) == 0
    assert "node 'AtHome?' needs a 'robot' resource and this tree has none; a stub stands in" \
        in caplog.text
    assert "done after 2 ticks; last root status SUCCESS" in capsys.readouterr().out
    sys.modules.pop("home_nodes", None)


def test_a_node_that_raises_in_bt_run_is_one_line_naming_it_never_a_traceback(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
        own_registered: None) -> None:
    (tmp_path / "sensor_nodes.py").write_text(HOME_NODES)
    monkeypatch.syspath_prepend(str(tmp_path))
    path = _write(tmp_path, project_json([tree_json(N("Broken", id="b", title="Read sensor"),
                                                    title="Broken")]))
    with _root_log_to_stderr():
        code = main(["bt", "run", str(path), "--nodes", "sensor_nodes", "--ticks", "2", "--fast"])
    assert code == 1  # the root ends in ERROR
    err = capsys.readouterr().err
    assert "Traceback" not in err
    errors = [line for line in err.splitlines() if "raised in tick" in line]
    assert len(errors) == 1, err  # said once: the second tick raises the same again
    assert "node b (Read sensor, Broken) raised in tick" in errors[0]
    assert "ValueError: the sensor is unplugged (at " in errors[0]
    assert "sensor_nodes.py:" in errors[0] and "in tick)" in errors[0]
    sys.modules.pop("sensor_nodes", None)


@contextmanager
def _root_log_to_stderr() -> Iterator[None]:
    """The root logger writes to this test's stderr, as `cyborg` configures it."""
    import logging

    root = logging.getLogger()
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(levelname)s %(name)s: %(message)s"))
    saved = root.handlers
    root.handlers = [handler]
    try:
        yield
    finally:
        root.handlers = saved


def test_the_readmes_node_package_loads_beside_the_robots_nodes_and_its_tree_is_refused(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
        own_registered: None) -> None:
    readme = (Path(__file__).parents[2] / "README.md").read_text()
    block = readme.split("# my_robot/nodes.py\n", 1)[1].split("```", 1)[0]
    (tmp_path / "readme_nodes.py").write_text(block)
    monkeypatch.syspath_prepend(str(tmp_path))
    assert main(["bt", "nodes", "--nodes", "readme_nodes"]) == 0
    listed = {line.split()[0]: line for line in capsys.readouterr().out.splitlines()}
    assert listed["Say"].endswith("[cyborg.robot.say]"), "the robot's Say stays the robot's"
    assert listed["Shout"].endswith("[readme_nodes]") and "AtHome?" in listed  # as it says
    path = _write(tmp_path, project_json([tree_json(N("AtHome?", id="home"), title="Home")]))
    assert main(["bt", "run", str(path), "--nodes", "readme_nodes", "--ticks", "1"]) == 2
    assert "1 node (AtHome?) need a robot" in capsys.readouterr().err
    sys.modules.pop("readme_nodes", None)
