"""Which messages a subscription has already delivered, per publisher: duplicates out, restarts in.

A message can reach a subscription twice: a shared-memory slot reference by the doorbell and
again through Zenoh (when one doorbell of several could not be rung), or a latched message from
the publisher's cache and live. Every sample carries rmw_zenoh's attachment with the publisher's
GID and a sequence number that grows by one per message, so the second copy is recognised by
``(GID, sequence)``.

Those two numbers are whatever the sender wrote. A GID is the hash of a public liveliness key,
so anyone can compute it, and nothing authenticates either number. The table therefore trusts
them only as far as the harm stays small:

* a sequence number is recorded only for a sample that was decoded and delivered, so one
  undecodable sample cannot mute a publisher;
* a number at most ``window`` below the last one recorded is a duplicate; one further back is
  a *restart* of the publisher (or a forgery) and is delivered, so a forged ``2**63 - 1``
  costs nothing, and a forged number slightly ahead of the real one hides at most ``window``
  messages;
* the table holds at most ``capacity`` publishers, least recently heard dropped first, so a
  flood of made-up GIDs cannot grow it; publishers that leave the graph are forgotten
  (:meth:`forget`). A dropped entry only means one later duplicate may get through.

    table = SequenceTable()
    if not table.seen(gid, sequence):        # cheap check before decoding
        message = decode(payload)            # may fail: nothing recorded then
        if table.record(gid, sequence):      # atomic check-and-record after decoding
            deliver(message)
"""

from __future__ import annotations

import threading
from collections import OrderedDict

MAX_PUBLISHERS = 1024
"""Publishers a subscription remembers sequence numbers of (least recently heard go first)."""

DUPLICATE_WINDOW = 1024
"""How far below the last sequence number a sample still counts as a duplicate; further back,
the publisher has restarted."""


class SequenceTable:
    """The last delivered sequence number of each publisher GID, bounded. Thread-safe.

    ``capacity`` and ``window`` are as the module doc describes them (ValueError below 1).
    """

    def __init__(self, capacity: int = MAX_PUBLISHERS, window: int = DUPLICATE_WINDOW) -> None:
        if capacity < 1 or window < 1:
            raise ValueError("a sequence table needs a capacity and a window of at least 1")
        self.capacity, self.window = capacity, window
        self._last: OrderedDict[bytes, int] = OrderedDict()
        self._lock = threading.Lock()

    def _duplicate(self, gid: bytes, sequence: int) -> bool:
        last = self._last.get(gid)
        return last is not None and last - self.window < sequence <= last

    def seen(self, gid: bytes, sequence: int) -> bool:
        """Whether ``sequence`` from ``gid`` was delivered already; records nothing."""
        with self._lock:
            return self._duplicate(gid, sequence)

    def record(self, gid: bytes, sequence: int) -> bool:
        """Remember ``sequence`` as delivered; False (and nothing changed) for a duplicate."""
        with self._lock:
            if self._duplicate(gid, sequence):
                return False
            last = self._last
            last[gid] = sequence
            last.move_to_end(gid)
            if len(last) > self.capacity:
                last.popitem(last=False)
            return True

    def forget(self, gid: bytes) -> None:
        """Drop a publisher, e.g. one that left the graph."""
        with self._lock:
            self._last.pop(gid, None)

    def __len__(self) -> int:
        return len(self._last)

    def __contains__(self, gid: object) -> bool:
        return gid in self._last
