"""A free local port for a test's own router or server, from one helper.

The operating system picks the port (binding port 0 on 127.0.0.1), so tests that run at the
same time, in one process or several, never choose the same one; the port is free when this
returns, and the caller binds it at once.
"""

from __future__ import annotations

import socket


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on now."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port


def local_endpoint() -> str:
    """A Zenoh endpoint on a free local port: ``tcp/127.0.0.1:PORT``."""
    return f"tcp/127.0.0.1:{free_port()}"
