"""Who may control the robot from a browser, and who does now.

The monitor shows the tree to anyone who can reach it, but control (run/pause, disable, force,
breakpoints, step) is a safety matter:

* A client may control only when it connects from the monitor's own machine (a loopback
  address) *through the monitor's own page* (or a script, which sends no ``Origin``), or
  presents the token the monitor was started with (``--token-file``,
  ``CYBORG_MONITOR_TOKEN`` or ``--token``). Everyone else is view-only; pages of other
  origins are not even let in without the token (see :mod:`cyborg.monitor.access`).
* Of the clients that may, one holds the **control seat** at a time. The first to ask gets it;
  another may take it over explicitly (``force``), and the previous holder is told.
* The seat belongs to the *connection* that took it (the number the server gave it), not to
  anything a page could show or say: what other pages hear is only that number, which no
  page can present. The holder alone is sent a random **secret**; a page that reloads, or whose
  link dropped, presents it in its ``hello`` and gets the seat back on its new connection.
* When the holder disconnects, the seat stays reserved for it for :data:`GRACE` seconds (other
  pages may take it over only explicitly); after that the seat is free and the hooks it set are
  released (as Groot2 releases a silent client's hooks).
"""

from __future__ import annotations

import ipaddress
import secrets
import time
from dataclasses import dataclass, field

from cyborg.monitor.access import same_secret
from cyborg.monitor.refusal import RefusalError

VIEW_ONLY = ("view only: control is accepted from the monitor's own page on this machine, or "
             "with the monitor's token")
"""Why a page that may not control is refused."""
NOT_HOLDER = "another page has control (or none was taken): take control first"
"""Why a page that may control but does not hold the seat is refused."""
GRACE = 10.0
"""Seconds the seat waits for a disconnected holder to come back."""
SECRET_BYTES = 16


def is_loopback(host: str | None) -> bool:
    """Whether ``host`` (a client address as the server saw it) is this machine."""
    if not host:
        return False
    try:
        address = ipaddress.ip_address(host.split("%", 1)[0])
    except ValueError:
        return False
    if isinstance(address, ipaddress.IPv6Address) and address.ipv4_mapped is not None:
        address = address.ipv4_mapped
    return address.is_loopback


@dataclass
class SeatHolder:
    """The connection that holds the control seat, or held it and may come back."""

    client: int
    """The number of the connection holding the seat (given by the server, never by a page)."""
    secret: str = field(default_factory=lambda: secrets.token_urlsafe(SECRET_BYTES), repr=False)
    """Sent to the holder only: it takes the seat back on a new connection."""
    connected: bool = True
    left_at: float = 0.0
    hooks: set[tuple[str, str]] = field(default_factory=set)
    """(namespace, node id) of the hooks this holder set and did not ask to keep."""


class ControlSeat:
    """The control seat: who may hold it, and who does now; see the module docstring.

    Clients are named by their connection numbers. ``token`` is the one the monitor was started
    with; ``grace`` the seconds the seat stays kept for a holder that left. Not thread-safe:
    use it from the web server's event loop.
    """

    def __init__(self, token: str | None = None, *, grace: float = GRACE) -> None:
        self.token = token or None
        self.grace = grace
        self.holder: SeatHolder | None = None

    def may_control(self, host: str | None, token: str | None) -> bool:
        """Whether a client at ``host`` presenting ``token`` may hold the seat.

        The caller checks that a loopback client's page is the monitor's own.
        """
        return is_loopback(host) or self.token_matches(token)

    def token_matches(self, token: str | None) -> bool:
        """Whether ``token`` is the monitor's (any Unicode; compared in constant time)."""
        return same_secret(token, self.token)

    def claim(self, client: int, *, force: bool = False) -> tuple[bool, int | None]:
        """Gives the seat to ``client``; returns (granted, the client it was taken from).

        A seat that is held, or kept for a holder that left, goes only with ``force``.
        """
        holder = self.holder
        if holder is not None and holder.client == client:
            return True, None
        if holder is not None and not force:
            return False, None
        self.holder = SeatHolder(client)
        if holder is None:
            return True, None
        self.holder.hooks = holder.hooks  # hooks stay with the seat, not the person
        return True, holder.client

    def resume(self, client: int, secret: str) -> bool:
        """Moves the seat to ``client`` if ``secret`` is the holder's; whether it moved.

        That is the holder's page on a new connection (a reload, a dropped link). The old
        connection loses the seat.
        """
        holder = self.holder
        if holder is None or not same_secret(secret, holder.secret):
            return False
        holder.client, holder.connected = client, True
        return True

    def holds(self, client: int) -> bool:
        """Whether ``client`` holds the seat now (not merely kept for it after it left)."""
        return self.holder is not None and self.holder.client == client and self.holder.connected

    def require(self, client: int, may_control: bool, *, seat: bool = True) -> None:
        """The one check before a command that acts; :class:`RefusalError` if it fails.

        ``client`` must be allowed to control (``may_control``: its page's origin or token)
        and, with ``seat``, hold the seat. A stop needs no seat (any page that may control
        sends one); everything else does.
        """
        if not may_control:
            raise RefusalError(VIEW_ONLY)
        if seat and not self.holds(client):
            raise RefusalError(NOT_HOLDER)

    def secret_for(self, client: int) -> str | None:
        """The seat's secret, for its holder only."""
        return self.holder.secret if self.holds(client) and self.holder else None

    def release(self, client: int) -> bool:
        """The holder gives the seat up (its hooks stay set); whether it held it."""
        if self.holder is not None and self.holder.client == client:
            self.holder = None
            return True
        return False

    def disconnected(self, client: int, now: float | None = None) -> bool:
        """``client``'s connection closed; whether it held the seat (kept for it a while)."""
        if self.holder is not None and self.holder.client == client:
            self.holder.connected = False
            self.holder.left_at = time.monotonic() if now is None else now
            return True
        return False

    def expired(self, now: float | None = None) -> set[tuple[str, str]] | None:
        """Frees the seat of a holder gone longer than the grace; the hooks it set, to release.

        None when the seat did not change. ``now`` defaults to ``time.monotonic()``.
        """
        holder = self.holder
        now = time.monotonic() if now is None else now
        if holder is None or holder.connected or now - holder.left_at < self.grace:
            return None
        self.holder = None
        return holder.hooks

    def note_hook(self, namespace: str, node_id: str, *, set_: bool) -> None:
        """Remember (or forget) a hook the holder set, to release it if the holder leaves."""
        if self.holder is None:
            return
        if set_:
            self.holder.hooks.add((namespace, node_id))
        else:
            self.holder.hooks.discard((namespace, node_id))
