"""The web monitor as a component: its parameters, their defaults, and how it starts.

:func:`start` is the ``monitor`` kind of launch files (see :mod:`cyborg.bus.component`) and
what ``cyborg monitor`` and ``cyborg up`` run: :class:`~cyborg.monitor.monitor.Monitor` on node
:data:`NAME`, with these read-only bus parameters:

===============  ===================================================================
parameter        meaning (default)
===============  ===================================================================
``trees``        tree runner namespaces to follow (:data:`TREES`: ``/cyborg/bt``)
``port``         web server port (:data:`PORT`, 8080; 0: any free port)
``host``         address to listen on (:data:`HOST`, 127.0.0.1: this machine only;
                 0.0.0.0: every interface)
``allow_hosts``  more names the page may be opened as (:data:`ALLOW_HOSTS`)
``token_file``   file holding the token for control from other machines (default:
                 ``$CYBORG_MONITOR_TOKEN``)
===============  ===================================================================

``token`` (the token itself) is read from the spec but never made a bus parameter: ``cyborg
param get`` would show it.
"""

from __future__ import annotations

from cyborg.bus import Context, Node
from cyborg.bus.component import NodeSpec
from cyborg.interfaces import robot, tree_runner
from cyborg.monitor.access import TokenError, read_token
from cyborg.monitor.monitor import DEFAULT_HOST, DEFAULT_PORT, Monitor, MonitorError

NAME = "monitor"
"""The monitor's node name unless told otherwise."""
NAMESPACE = robot.NAMESPACE
"""The monitor's namespace unless told otherwise (the robot's, ``/cyborg``)."""
TREES = (tree_runner.NAMESPACE,)
"""The tree runners' namespaces the monitor follows unless told otherwise."""
PORT = DEFAULT_PORT
"""The web server's port unless told otherwise."""
HOST = DEFAULT_HOST
"""The address the web server listens on unless told otherwise: this machine only."""
ALLOW_HOSTS = ("localhost",)
"""The names the page may be opened as, beside this machine's, unless told otherwise."""


class RunningMonitor:
    """A started web monitor."""

    def __init__(self, monitor: Monitor) -> None:
        self.monitor = monitor

    def describe(self) -> str:
        """Where to open the page, the trees it follows, and how exposed it is."""
        urls = self.monitor.urls()
        others = (f" (from other machines: {', '.join(urls[1:])})" if urls[1:] else
                  " (this machine only)" if self.monitor.on_loopback else "")
        line = (f"monitor      {self.monitor.node.fq_name}: open {urls[0]}{others}; trees "
                f"{', '.join(sorted(self.monitor.hub.sources))}")
        exposure = self.monitor.exposure()
        return f"{line}\n               {exposure}" if exposure else line

    def stop(self) -> None:
        """Stops serving and leaves the bus."""
        self.monitor.stop()


def start(context: Context, spec: NodeSpec) -> RunningMonitor:
    """Starts the monitor from ``spec``; a taken port or a bad token file refuses it."""
    # the token is a secret: read here, never declared (`cyborg param get` would show it)
    parameters = {name: value for name, value in spec.parameters.items() if name != "token"}
    node = Node(spec.name, spec.namespace, context=context, parameters=parameters)
    try:
        params = node.parameters
        trees = params.declare("trees", list(TREES), "tree runner namespaces to follow",
                               read_only=True)
        port = params.declare("port", PORT, "web server port (0: any free port)",
                              read_only=True)
        host = params.declare("host", HOST, "address to listen on (0.0.0.0: every "
                              "interface)", read_only=True)
        allow_hosts = params.declare("allow_hosts", list(ALLOW_HOSTS), "names the page may be "
                                     "opened as, beside this machine's", read_only=True)
        token_file = params.declare("token_file", "", "file holding the token for control "
                                    "from other machines", read_only=True)
        try:
            token = read_token(str(spec.parameters.get("token") or "") or None,
                               spec.path(str(token_file)) if token_file else None)
            monitor = Monitor(node, namespaces=[str(tree) for tree in trees], host=str(host),
                              port=int(port), token=token,
                              allow_hosts=[str(name) for name in allow_hosts])
        except TokenError as exc:
            raise spec.error(str(exc)) from None
        except ValueError as exc:
            raise spec.error(f"trees: {exc}") from None
        try:
            monitor.start()
        except MonitorError as exc:
            raise spec.error(str(exc)) from exc
    except BaseException:
        node.destroy()
        raise
    return RunningMonitor(monitor)
