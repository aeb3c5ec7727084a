"""Who may control the robot from a browser, and who does now.

The monitor shows the tree to anyone who can reach it, but control (run/pause, disable, force,
breakpoints, step) is a safety matter:

* A client may control only when it connects from the monitor's own machine (a loopback
  address), or presents the token the monitor was started with (``--token`` or
  ``CYBORG_MONITOR_TOKEN``). Everyone else is view-only.
* Of the clients that may, one holds the **control seat** at a time. The first to ask gets it;
  another may take it over explicitly (``force``), and the previous holder is told.
* When the holder disconnects, the seat stays reserved for it for :data:`GRACE` seconds (a
  reload or a dropped Wi-Fi link comes back with the same client key); after that the seat is
  free and the hooks it set are released (as Groot2 releases a silent client's hooks).
"""

from __future__ import annotations

import hmac
import ipaddress
import time
from dataclasses import dataclass, field

GRACE = 10.0
"""Seconds the seat waits for a disconnected holder to come back."""


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
    key: str
    """The client's key (chosen by the page, kept across reloads of the same tab)."""
    connected: bool = True
    left_at: float = 0.0
    hooks: set[tuple[str, str]] = field(default_factory=set)
    """(namespace, node id) of the hooks this holder set and did not ask to keep."""


class ControlSeat:
    """See the module docstring. Not thread-safe: use it from the web server's event loop."""

    def __init__(self, token: str | None = None, *, grace: float = GRACE) -> None:
        self.token = token or None
        self.grace = grace
        self.holder: SeatHolder | None = None

    def may_control(self, host: str | None, token: str | None) -> bool:
        """Whether a client at ``host`` presenting ``token`` may hold the seat."""
        if is_loopback(host):
            return True
        return bool(self.token and token and hmac.compare_digest(token, self.token))

    def claim(self, key: str, *, force: bool = False) -> tuple[bool, str | None]:
        """Give the seat to ``key``; returns (granted, key of the holder it was taken from)."""
        holder = self.holder
        if holder is not None and holder.key == key:
            holder.connected = True
            return True, None
        if holder is not None and holder.connected and not force:
            return False, None
        previous = holder.key if holder is not None else None
        self.holder = SeatHolder(key)
        if holder is not None:
            self.holder.hooks = holder.hooks  # hooks stay with the seat, not the person
        return True, previous

    def holds(self, key: str) -> bool:
        return self.holder is not None and self.holder.key == key and self.holder.connected

    def release(self, key: str) -> None:
        """The holder gives the seat up (its hooks stay set)."""
        if self.holder is not None and self.holder.key == key:
            self.holder = None

    def disconnected(self, key: str, now: float | None = None) -> None:
        if self.holder is not None and self.holder.key == key:
            self.holder.connected = False
            self.holder.left_at = time.monotonic() if now is None else now

    def expired(self, now: float | None = None) -> set[tuple[str, str]] | None:
        """Free the seat of a holder gone longer than the grace and return the hooks it set
        (to release); None when the seat did not change."""
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
