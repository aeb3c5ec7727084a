"""The Foxglove server as a component: its parameters, their defaults, and how it starts.

:func:`start` is the ``foxglove`` kind of launch files (see :mod:`cyborg.bus.component`) and
what ``cyborg foxglove`` and ``cyborg up --foxglove`` run: a
:class:`~cyborg.foxglove.server.FoxgloveServer` on node :data:`NAME`, with these read-only bus
parameters:

=================  ===================================================================
parameter          meaning (default)
=================  ===================================================================
``port``           WebSocket port (:data:`PORT`, 8765; 0: any free port)
``host``           address to listen on (:data:`HOST`, 127.0.0.1: this machine only;
                   another needs a token)
``allow_hosts``    more names clients may connect as (:data:`ALLOW_HOSTS`)
``allow_origins``  web pages that may connect from this machine without the token
                   (:data:`ALLOW_ORIGINS`: the Foxglove app; ``*``: any)
``token_file``     file holding the token for other machines (default:
                   ``$CYBORG_MONITOR_TOKEN``)
=================  ===================================================================

``token`` (the token itself) is read from the spec but never made a bus parameter: ``cyborg
param get`` would show it.
"""

from __future__ import annotations

from cyborg.access import TokenError, read_token
from cyborg.bus import Context, Node
from cyborg.bus.component import NodeSpec
from cyborg.foxglove.admission import FOXGLOVE_ORIGINS
from cyborg.foxglove.server import DEFAULT_HOST, DEFAULT_PORT, FoxgloveError, FoxgloveServer
from cyborg.interfaces import robot

NAME = "foxglove"
"""The server's node name unless told otherwise."""
NAMESPACE = robot.NAMESPACE
"""The server's namespace unless told otherwise (the robot's, ``/cyborg``)."""
PORT = DEFAULT_PORT
"""The WebSocket port unless told otherwise."""
HOST = DEFAULT_HOST
"""The address listened on unless told otherwise: this machine only."""
ALLOW_HOSTS = ("localhost",)
"""The names clients may connect as, beside this machine's, unless told otherwise."""
ALLOW_ORIGINS = FOXGLOVE_ORIGINS
"""The web pages that may connect from this machine without the token, unless told otherwise."""


class RunningFoxglove:
    """A started Foxglove server."""

    def __init__(self, server: FoxgloveServer) -> None:
        self.server = server

    def describe(self) -> str:
        """Where to connect Foxglove, and how exposed the server is."""
        where = " (this machine only)" if self.server.on_loopback else ""
        line = (f"foxglove     {self.server.node.fq_name}: open {self.server.url()}{where} in "
                "Foxglove (Open connection > Foxglove WebSocket)")
        exposure = self.server.exposure()
        return f"{line}\n               {exposure}" if exposure else line

    def stop(self) -> None:
        """Stops serving and leaves the bus."""
        self.server.stop()
        self.server.node.destroy()


def start(context: Context, spec: NodeSpec) -> RunningFoxglove:
    """Starts the server from ``spec``; a taken port, a bad token file or no token refuse it."""
    # the token is a secret: read here, never declared (`cyborg param get` would show it)
    parameters = {name: value for name, value in spec.parameters.items() if name != "token"}
    node = Node(spec.name, spec.namespace, context=context, parameters=parameters)
    try:
        params = node.parameters
        port = params.declare("port", PORT, "WebSocket port (0: any free port)", read_only=True)
        host = params.declare("host", HOST, "address to listen on (another than loopback "
                              "needs a token)", read_only=True)
        allow_hosts = params.declare("allow_hosts", list(ALLOW_HOSTS), "names clients may "
                                     "connect as, beside this machine's", read_only=True)
        allow_origins = params.declare("allow_origins", list(ALLOW_ORIGINS), "web pages that "
                                       "may connect from this machine without the token",
                                       read_only=True)
        token_file = params.declare("token_file", "", "file holding the token for other "
                                    "machines", read_only=True)
        try:
            token = read_token(str(spec.parameters.get("token") or "") or None,
                               spec.path(str(token_file)) if token_file else None)
        except TokenError as exc:
            raise spec.error(str(exc)) from None
        try:
            server = FoxgloveServer(node, host=str(host), port=int(port), token=token,
                                    allow_hosts=[str(name) for name in allow_hosts if name],
                                    allow_origins=[str(name) for name in allow_origins if name])
        except ValueError as exc:
            raise spec.error(str(exc)) from None
        try:
            server.start()
        except FoxgloveError as exc:
            raise spec.error(str(exc)) from None
    except BaseException:
        node.destroy()
        raise
    return RunningFoxglove(server)
