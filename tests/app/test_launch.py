"""Launch files, `cyborg launch` across processes, `cyborg up`, and the runner's CLI controls."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path
from typing import Any

import pytest

from cyborg.app.cli import main
from cyborg.app.launch import Launch, read_launch
from cyborg.bus import BusConfig, Context, SimClock
from cyborg.bus.component import LaunchError
from cyborg.runner.component import RunningTree
from cyborg.sim.component import RunningSimulator
from tests.ports import free_port
from tests.running_system import interruptible


def _launch_file(folder: Path, shared: Path, *, port: int = 7447, process: str = "main",
                 extra: str = "") -> Path:
    path = folder / "robot.toml"
    path.write_text(f'''
[bus]
listen = "tcp/127.0.0.1:{port}"

[[node]]
kind = "simulator"
name = "arnl"
namespace = "/cyborg"
process = "{process}"
parameters = {{ map = "{shared / 'maps' / 'AMROffice.map'}", speed = 10, start = "Dock" }}

[[node]]
kind = "tree_runner"
name = "tree_runner"
namespace = "/cyborg/bt"
parameters = {{ tree_file = "{shared / 'trees' / 'patrol_recharge.b3.json'}", use_sim_time = true }}
{extra}''')
    return path


@pytest.mark.parametrize(("text", "expected"), [
    ("[[node]\nkind = 1", "robot.toml: not valid TOML: "),
    ("[extras]\na = 1", "unknown section(s) extras"),
    ("", "no [[node]] entries: nothing to launch"),
    ('[[node]]\nname = "x"', "robot.toml: node 1: field `kind` is missing"),
    ('[[node]]\nkind = "simulator"\nname = "x"\ncolour = "red"', "unknown field(s) colour"),
    ('[[node]]\nkind = "teleporter"\nname = "x"', "node 1 (x): unknown kind 'teleporter'"),
    ('[[node]]\nkind = "nowhere.module:start"\nname = "x"', "cannot load kind"),
    ('[[node]]\nkind = "simulator"\nname = "x"\nparameters = 3', "`parameters` must be a table"),
    ('[[node]]\nkind = "simulator"\nname = "x"\n[[node]]\nkind = "simulator"\nname = "x"',
     "node 2 (x): another node is already called /x"),
])
def test_bad_launch_files_name_the_file_node_and_field(tmp_path: Path, text: str,
                                                       expected: str) -> None:
    path = tmp_path / "robot.toml"
    path.write_text(text)
    with pytest.raises(LaunchError) as error:
        read_launch(path)
    assert expected in str(error.value)
    assert str(path) in str(error.value) or "robot.toml" in str(error.value)


def test_bad_yaml_names_the_line(tmp_path: Path) -> None:
    path = tmp_path / "robot.yaml"
    path.write_text("node:\n  - kind: simulator\n    name: [unclosed\n")
    with pytest.raises(LaunchError, match=r"robot.yaml:\d+: not valid YAML"):
        read_launch(path)


def test_yaml_launch_is_the_same_as_toml(tmp_path: Path) -> None:
    path = tmp_path / "robot.yaml"
    path.write_text("node:\n  - kind: tree_runner\n    name: runner\n    namespace: /r1/bt\n"
                    "    process: brain\n    parameters: {tree_file: t.json, rate: 5}\n")
    description = read_launch(path)
    (spec,) = description.nodes
    assert (spec.kind, spec.name, spec.namespace, spec.process) == (
        "tree_runner", "runner", "/r1/bt", "brain")
    assert spec.path("t.json") == tmp_path / "t.json"
    assert description.processes() == ["main", "brain"]


def test_a_byte_order_mark_is_read_past_and_other_encodings_are_named(tmp_path: Path) -> None:
    text = "[[node]]\nkind = \"tree_runner\"\nname = \"runner\"\n"
    for suffix, body in ((".toml", text),
                         (".yaml", "node:\n  - kind: tree_runner\n    name: runner\n")):
        path = tmp_path / f"bom{suffix}"
        path.write_bytes(b"\xef\xbb\xbf" + body.encode())
        assert [spec.name for spec in read_launch(path).nodes] == ["runner"]
    latin = tmp_path / "latin.toml"
    latin.write_bytes(text.encode() + b"# Kj\xf8kken\n")
    with pytest.raises(LaunchError, match=r"latin.toml:4: not UTF-8 text \(byte 50"):
        read_launch(latin)


def test_nodes_that_cannot_start_stop_what_started(tmp_path: Path, shared: Path) -> None:
    broken_tree = tmp_path / "broken.b3.json"
    broken_tree.write_text('{"trees": [}')
    path = _launch_file(tmp_path, shared).read_text().replace(
        str(shared / "trees" / "patrol_recharge.b3.json"), str(broken_tree))
    (tmp_path / "robot.toml").write_text(path)
    with Context(BusConfig.isolated()) as context:
        launch = Launch(read_launch(tmp_path / "robot.toml"), context)
        with pytest.raises(LaunchError, match="the tree file has errors") as error:
            launch.start()
        assert "broken.b3.json:1" in str(error.value)
        assert launch.running == [], "the simulator that had started was stopped again"
    missing = tmp_path / "missing.toml"
    missing.write_text('[[node]]\nkind = "simulator"\nname = "arnl"\n'
                       'parameters = { map = "nowhere.map" }\n')
    with Context(BusConfig.isolated()) as context, \
            pytest.raises(LaunchError, match=r"missing.toml: node 1 \(arnl\): .*nowhere.map"):
        Launch(read_launch(missing), context).start()


def test_the_clock_limits_are_launch_parameters(tmp_path: Path, shared: Path) -> None:
    text = _launch_file(tmp_path, shared).read_text().replace(
        "use_sim_time = true }", "use_sim_time = true, clock_jump_limit = 2.5, "
        "clock_stall_timeout = 30 }")
    (tmp_path / "robot.toml").write_text(text)
    with Context(BusConfig.isolated()) as context:
        launch = Launch(read_launch(tmp_path / "robot.toml"), context)
        launch.start()
        try:
            clock = launch.running[1].runner.clock  # type: ignore[attr-defined]
            assert isinstance(clock, SimClock)
            assert (clock.jump_limit, clock.stall_timeout) == (2.5, 30.0)
        finally:
            launch.stop()
    (tmp_path / "robot.toml").write_text(text.replace("clock_jump_limit = 2.5",
                                                      "clock_jump_limit = -1"))
    with Context(BusConfig.isolated()) as context, \
            pytest.raises(LaunchError, match=r"robot.toml: node 2 \(tree_runner\): parameter "
                                             r"'clock_jump_limit': -1.0 is outside"):
        Launch(read_launch(tmp_path / "robot.toml"), context).start()


def test_launch_in_one_process(tmp_path: Path, shared: Path) -> None:
    with Context(BusConfig.isolated()) as context:
        launch = Launch(read_launch(_launch_file(tmp_path, shared)), context)
        launch.start()
        try:
            kinds = [type(item) for item in launch.running]
            assert kinds == [RunningSimulator, RunningTree]
            lines = launch.describe()
            assert "simulator    /cyborg/arnl: AMROffice.map at 10x real time" in lines[0]
            assert "tree runner  /cyborg/bt/tree_runner: 'Root tree' (18 nodes)" in lines[1]
            simulator = launch.running[0]
            assert isinstance(simulator, RunningSimulator)
            simulator.node.parameters.set({"speed": 0.0})  # `cyborg param set` does this
            deadline = time.monotonic() + 5
            while simulator.loop.speed != float("inf"):
                assert time.monotonic() < deadline, "the speed parameter was not applied"
                time.sleep(0.01)
            with pytest.raises(ValueError, match="speed must be positive"):
                simulator.node.parameters.set({"speed": -1.0})
            simulator.node.parameters.set({"speed": 10.0})
            runner = launch.running[1].runner  # type: ignore[attr-defined]
            deadline = time.monotonic() + 20
            while runner.tree.ticks < 20:
                assert time.monotonic() < deadline
                time.sleep(0.05)
        finally:
            launch.stop()
        assert launch.running == []


@pytest.mark.heavy
def test_launch_across_processes_and_control_from_the_shell(
        tmp_path: Path, shared: Path, capsys: pytest.CaptureFixture[str]) -> None:
    port = free_port()
    path = _launch_file(tmp_path, shared, port=port, process="robot")
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    parent = subprocess.Popen([sys.executable, "-m", "cyborg", "launch", str(path)],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=env,
                              preexec_fn=interruptible)
    endpoint = f"tcp/127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + 60
        while True:
            assert time.monotonic() < deadline, "the launched nodes did not appear"
            if main(["node", "list", "--connect", endpoint, "--wait", "0.5"]) == 0:
                out = capsys.readouterr().out
                if "/cyborg/arnl" in out and "/cyborg/bt/tree_runner" in out:
                    break
            time.sleep(0.5)
        assert main(["bt", "disable", "--connect", endpoint]) == 0
        assert "disabled" in capsys.readouterr().out
        bad = tmp_path / "bad.b3.json"
        bad.write_text('{"trees": [\n}')
        assert main(["bt", "reload", str(bad), "--connect", endpoint]) == 1
        assert f"{bad}:2" in capsys.readouterr().out
        assert main(["bt", "reload", "--connect", endpoint]) == 0
        assert "loaded 'Root tree' (18 nodes)" in capsys.readouterr().out
        assert main(["bt", "stop", "--connect", endpoint]) == 0
        assert capsys.readouterr().out.startswith("stopped: the tree is halted until")
        assert main(["bt", "enable", "--connect", endpoint]) == 0
    finally:
        parent.send_signal(signal.SIGINT)
        output = parent.communicate(timeout=30)[0].decode()
    assert parent.returncode == 130, output
    assert "process      robot (pid" in output and "tree runner  /cyborg/bt/tree_runner" in output
    assert "stopped" in output


@pytest.mark.heavy
def test_cyborg_up_runs_the_bundled_system() -> None:
    port = free_port()
    process = subprocess.Popen(
        [sys.executable, "-m", "cyborg", "up", "--speed", "20", "--duration", "8",
         "--listen", f"tcp/127.0.0.1:{port}", "--monitor-port", "0"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1"))
    assert process.stdout is not None
    lines: list[str] = []
    while not any("monitor      /cyborg/monitor: open " in line for line in lines):
        line = process.stdout.readline()
        assert line, "cyborg up ended before printing the monitor's address"
        lines.append(line)
    url = lines[-1].split("open ")[1].split()[0]
    assert url.startswith("http://127.0.0.1:")
    deadline = time.monotonic() + 20
    robots: dict[str, Any] = {}
    while time.monotonic() < deadline:
        robots = json.loads(urllib.request.urlopen(url + "api/robots", timeout=5).read())
        if robots["robots"] and robots["robots"][0]["alive"] and robots["robots"][0]["tick"]:
            break
        time.sleep(0.2)
    assert robots["robots"][0]["title"] == "Patrol", robots  # the tree of the mode `normal`
    page = urllib.request.urlopen(url, timeout=5).read().decode()
    assert "<title>cyborg monitor</title>" in page
    rest = process.stdout.read()  # what the text wrapper has read ahead stays in it
    assert process.wait(timeout=120) == 0, rest + (process.stderr.read() if process.stderr else "")
    out = "".join(lines) + rest
    assert "simulator    /cyborg/arnl: campus.map at 20x real time" in out
    assert ("tree runner  /cyborg/bt/tree_runner: 4 modes, in 'normal' ('Patrol', 24 nodes) "
            "from campus.modes.toml") in out
    assert ("Patrol > Sequence > Repeat -1x > Greet or patrol > Patrol round > "
            "MoveTo Lecture hall") in out
    assert "MoveTo Library" in out, "the robot got to the lecture hall and went on"


def test_cyborg_monitor_serves_and_a_taken_port_is_a_clear_error() -> None:
    bus = free_port()
    with socket.socket() as taken:
        taken.bind(("0.0.0.0", 0))
        taken.listen()
        port = taken.getsockname()[1]
        refused = subprocess.run(
            [sys.executable, "-m", "cyborg", "monitor", "--port", str(port), "--duration", "5",
             "--listen", f"tcp/127.0.0.1:{bus}"], capture_output=True, text=True, timeout=60)
    assert refused.returncode == 1
    assert f"cannot listen on 127.0.0.1:{port}" in refused.stderr
    assert "choose another port with --port" in refused.stderr
    assert "Traceback" not in refused.stderr
    process = subprocess.Popen(
        [sys.executable, "-m", "cyborg", "monitor", "--port", "0", "--duration", "4",
         "--namespace", "robot1/bt", "--listen", f"tcp/127.0.0.1:{bus}"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1"))
    assert process.stdout is not None
    line = ""
    while "open http" not in line:
        line = process.stdout.readline()
        assert line, "cyborg monitor ended before printing its address"
    url = line.split("open ")[1].split()[0]
    stats = json.loads(urllib.request.urlopen(url + "stats", timeout=5).read())
    assert stats["trees"] == ["/robot1/bt"]
    assert process.wait(timeout=60) == 0


def test_a_stop_that_hangs_ends_the_process_and_says_where() -> None:
    """Ctrl-C always ends `cyborg up` / `cyborg launch`: a part that does not stop within the
    deadline is named, with every thread's stack, and the process exits."""
    script = ("import time\n"
              "from cyborg.app.launch import end_if_stuck\n"
              "class Stuck:\n"
              "    stopping = 'tree runner /cyborg/bt/tree_runner'\n"
              "end_if_stuck(Stuck(), deadline=0.5)\n"
              "time.sleep(60)  # a stop that never ends\n")
    started = time.monotonic()
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=30)
    assert time.monotonic() - started < 20
    assert done.returncode == 1
    assert ("still stopping after 0.5 s, at: tree runner /cyborg/bt/tree_runner"
            in done.stderr)
    assert "most recent call first" in done.stderr  # the threads' stacks
