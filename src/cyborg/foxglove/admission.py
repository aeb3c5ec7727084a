"""Who may open the Foxglove connection: the monitor's rules, applied to a WebSocket handshake.

The Foxglove server shows everything on the bus, so the rules are those of the monitor
(:mod:`cyborg.access`) where it only lets people watch, and a little stricter:

* It listens on loopback unless told otherwise; listening beyond it (``--host 0.0.0.0``) needs
  a token, or it does not start (:func:`check_binding`).
* Every handshake must name this machine in its ``Host`` header, or a name allowed with
  ``--allow-host`` (:class:`~cyborg.access.HostPolicy`, the guard against DNS rebinding).
* A handshake that presents the token (``?token=...`` in the address, or an ``Authorization:
  Bearer ...`` header) is let in.
* Without it, only a client on this machine is let in, and from a web page only if the page is
  the Foxglove app (:data:`FOXGLOVE_ORIGINS`), another origin allowed with ``--allow-origin``,
  or the server's own origin: any other site open in the browser could otherwise read the
  robot's bus through ``ws://127.0.0.1:8765``. Programs that send no ``Origin`` are let in.

:func:`parse_handshake` reads the request line and headers; :meth:`Admission.refusal` says why a
handshake is refused, or None.
"""

from __future__ import annotations

import ipaddress
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from urllib.parse import parse_qs, urlsplit

from cyborg.access import HostPolicy, own_origin, same_secret

FOXGLOVE_ORIGINS = ("https://app.foxglove.dev",)
"""The web pages that may connect from this machine without the token: the Foxglove app."""
HANDSHAKE_LIMIT = 16 * 1024
"""The most bytes a handshake's request line and headers may take."""


class AdmissionError(ValueError):
    """The server cannot listen as asked (beyond loopback without a token); says what to do."""


@dataclass(frozen=True)
class Handshake:
    """A WebSocket handshake as received: the request target and its headers (lower-cased)."""

    method: str
    target: str
    headers: Mapping[str, str] = field(default_factory=dict)

    @property
    def token(self) -> str | None:
        """The token presented: ``?token=`` in the target, else a bearer token, else None."""
        query = parse_qs(urlsplit(self.target).query).get("token")
        if query:
            return query[0]
        scheme, _, value = self.headers.get("authorization", "").partition(" ")
        return value.strip() or None if scheme.lower() == "bearer" else None


def parse_handshake(head: bytes) -> Handshake:
    """The request line and headers of ``head`` (up to the blank line); ValueError if malformed."""
    lines = head.decode("latin-1").split("\r\n")  # HTTP's header bytes, each kept as it is
    parts = lines[0].split(" ")
    if len(parts) != 3 or not parts[2].startswith("HTTP/"):
        raise ValueError(f"not an HTTP request line: {lines[0][:80]!r}")
    headers: dict[str, str] = {}
    for line in lines[1:]:
        if not line:
            continue
        name, colon, value = line.partition(":")
        if not colon or not name.strip():
            raise ValueError(f"not a header line: {line[:80]!r}")
        headers[name.strip().lower()] = value.strip()
    return Handshake(parts[0], parts[1], headers)


def is_loopback(host: str) -> bool:
    """Whether ``host`` (an address or ``localhost``) is this machine's loopback only."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def check_binding(host: str, token: str | None) -> None:
    """Refuse to listen on ``host`` beyond loopback without a token (AdmissionError)."""
    if not is_loopback(host) and not token:
        raise AdmissionError(
            f"--host {host} lets other machines read the whole bus: set a token first "
            "(--token-file PATH or $CYBORG_MONITOR_TOKEN; clients then connect with "
            "?token=...), or keep the default 127.0.0.1")


class Admission:
    """The rules for one server: its ``hosts`` policy, its ``token`` and extra ``origins``."""

    def __init__(self, hosts: HostPolicy, token: str | None,
                 origins: Iterable[str] = ()) -> None:
        self.hosts, self.token = hosts, token
        extra = [origin.strip().rstrip("/").lower() for origin in origins if origin.strip()]
        self.any_origin = "*" in extra
        self.origins = {*FOXGLOVE_ORIGINS, *extra}

    def refusal(self, handshake: Handshake, *, peer_loopback: bool) -> str | None:
        """Why ``handshake`` from a peer (on loopback or not) is refused; None: let it in."""
        host = handshake.headers.get("host")
        if not self.hosts.allows(host):
            return self.hosts.refusal(host)
        if self.token and same_secret(handshake.token, self.token):
            return None
        if handshake.token is not None:
            return "403: wrong token\n"
        if not peer_loopback:
            return "403: connections from other machines need the token (?token=...)\n"
        origin = handshake.headers.get("origin")
        if origin is None or self.any_origin or origin.rstrip("/").lower() in self.origins \
                or own_origin(origin, "ws", host):
            return None
        return (f"403: the web page {origin!r} may not read this bus (only the Foxglove app "
                f"may, or origins given with --allow-origin)\n")
