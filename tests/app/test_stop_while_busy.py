"""Nothing a node does takes away the stop: while a node of `cyborg bt serve`'s tree loops in
Python for ever, `enable(false)` answers within 0.5 s and SIGTERM ends the process within 2 s."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from cyborg.bus import BusConfig, Context, Node, new_message
from tests.ports import free_port
from tests.running_system import wait_until, write_tree

BUSY_NODES = '''
"""A node that loops for ever on its second tick, noting each spin in a file."""
import os
from cyborg.bt import Action, RUNNING, register


@register
class Spin(Action):
    """RUNNING, then a loop that never ends."""

    def on_start(self):
        self.ticked = 0

    def tick(self):
        self.ticked += 1
        if self.ticked == 1:
            return RUNNING
        with open(os.environ["SPIN_LOG"], "a") as log:
            log.write("spin\\n")
        while True:
            pass
'''


def spins(log: Path) -> int:
    return log.read_text().count("spin") if log.exists() else 0


def test_enable_false_and_sigterm_answer_while_a_node_spins(tmp_path: Path) -> None:
    (tmp_path / "busy_spin_nodes.py").write_text(BUSY_NODES)
    tree = write_tree(tmp_path, {"name": "Spin"})
    spin_log = tmp_path / "spins.log"
    port = free_port()
    env = dict(os.environ, PYTHONPATH=f"{tmp_path}{os.pathsep}{os.environ.get('PYTHONPATH', '')}",
               SPIN_LOG=str(spin_log))
    server = subprocess.Popen(
        [sys.executable, "-m", "cyborg", "bt", "serve", str(tree), "--nodes", "busy_spin_nodes",
         "--listen", f"tcp/127.0.0.1:{port}"],
        env=env, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    context = Context(BusConfig(connect=(f"tcp/127.0.0.1:{port}",), listen=()))
    try:
        wait_until(lambda: spins(spin_log) == 1, timeout=60, what="the node to spin")
        client = Node("tester", "/test", context=context).create_client(
            "/cyborg/bt/enable", "std_srvs/srv/SetBool")
        assert client.wait_for_service(10.0)
        off = new_message(client.node.types, "std_srvs/srv/SetBool_Request", {"data": False})
        started = time.monotonic()
        reply = client.call_async(off, 5.0).result(5.0)
        took = time.monotonic() - started
        assert took < 0.5, f"enable(false) took {took:.2f} s while a node spun"
        assert reply.success and reply.message == "disabled", reply.message  # halted, complete

        on = new_message(client.node.types, "std_srvs/srv/SetBool_Request", {"data": True})
        assert client.call_async(on, 5.0).result(5.0).success
        wait_until(lambda: spins(spin_log) == 2, timeout=10, what="the node to spin again")
        started = time.monotonic()
        server.send_signal(signal.SIGTERM)
        code = server.wait(10)
        took = time.monotonic() - started
        assert took < 2.0, f"SIGTERM took {took:.2f} s to end the process while a node spun"
        assert code == 130
    finally:
        context.close()
        if server.poll() is None:
            server.kill()
            server.wait()
    output = server.stdout.read() if server.stdout else ""
    assert "Traceback" not in output, output
