"""Slot references to subscribers on this machine, by Unix datagram: the *doorbell*.

A large message crosses processes in a shared-memory slot (:mod:`cyborg.bus.shm`); only a
reference of a few dozen bytes has to travel. Through Zenoh that reference takes a trip through
two of Zenoh's threads and a TCP connection, 0.3 to 0.4 ms on a machine that has just woken up,
and it waits for the publisher's interpreter lock. A Unix datagram sent from the publisher's
own thread reaches a thread blocked in ``recv`` in the subscriber's process in about 0.1 ms.

Each :class:`~cyborg.bus.context.Context` owns one doorbell: a datagram socket in Linux's
abstract namespace (no file to clean up; it vanishes with the process), named after the
domain and the session's Zenoh id. Subscriptions that read shared memory already announce
themselves with a liveliness token holding that id and their entity id, so a publisher knows
where to ring without any further discovery.

A datagram holds the subscriber's entity id, the rmw_zenoh attachment and the slot reference::

    <uint32 entity id> <uint16 attachment length> <attachment> <slot reference>

Whatever cannot be rung (no such socket: an older process, another network namespace, a full
queue) makes the publisher send the reference through Zenoh as before; subscriptions drop the
second copy by its sequence number. Malformed datagrams are counted as dropped input.

An abstract socket has no file permissions: any local user who learns the name can send to
it. The doorbell therefore asks the kernel for each sender's credentials (``SO_PASSCRED``) and
drops datagrams from other users; slot files are the user's own (mode 0600) anyway, and a
reference that names anything else is refused by :func:`cyborg.bus.shm.open_slot`.
"""

from __future__ import annotations

import contextlib
import logging
import os
import socket
import struct
import sys
import threading
from collections.abc import Callable, Iterable

log = logging.getLogger("cyborg.bus")

_HEAD = struct.Struct("<IH")  # entity id, attachment length
_CREDENTIALS = struct.Struct("iII")  # struct ucred: pid, uid, gid
_MAX_DATAGRAM = 4096
_STOP = b""

Handler = Callable[[bytes, bytes], object]
"""Called on the doorbell's thread with (attachment, slot reference) of one message."""


def doorbell_address(domain: int, zid: str) -> str:
    """The abstract socket name of the session ``zid``'s doorbell (leading NUL: abstract)."""
    return f"\0cyborg-doorbell/{domain}/{zid}"


def supported() -> bool:
    """Abstract Unix sockets exist on Linux only; elsewhere references go through Zenoh."""
    return sys.platform.startswith("linux")


def encode(entity_id: int, attachment: bytes, reference: bytes) -> bytes:
    """One datagram for subscription ``entity_id``, the inverse of :func:`decode`."""
    return _HEAD.pack(entity_id, len(attachment)) + attachment + reference


def decode(datagram: bytes) -> tuple[int, bytes, bytes]:
    """(entity id, attachment, reference); ValueError for anything else."""
    if len(datagram) < _HEAD.size:
        raise ValueError(f"doorbell datagram of {len(datagram)} bytes is too short")
    entity_id, attachment_length = _HEAD.unpack_from(datagram)
    end = _HEAD.size + attachment_length
    if end > len(datagram):
        raise ValueError(f"doorbell datagram announces {attachment_length} attachment bytes, "
                         f"holds {len(datagram) - _HEAD.size}")
    return entity_id, datagram[_HEAD.size:end], datagram[end:]


def sender_uid(ancillary: list[tuple[int, int, bytes]]) -> int | None:
    """The sending process's user id from ``SCM_CREDENTIALS`` ancillary data (None if absent)."""
    for level, kind, data in ancillary:
        if level == socket.SOL_SOCKET and kind == socket.SCM_CREDENTIALS \
                and len(data) >= _CREDENTIALS.size:
            return int(_CREDENTIALS.unpack_from(data)[1])
    return None


class Doorbell:
    """One session's doorbell: rings others' (:meth:`ring`), answers its own on a thread.

    ``domain`` and ``zid`` (the session's Zenoh id) name its socket; ``drop(reason, detail)``
    counts a rejected datagram (:meth:`Context.drop <cyborg.bus.context.Context.drop>`).
    Raises OSError if the socket cannot be bound, e.g. when the name is taken.
    """

    def __init__(self, domain: int, zid: str,
                 drop: Callable[[str, str], None]) -> None:
        self.domain = domain
        self.address = doorbell_address(domain, zid)
        self._drop = drop
        self.answered = 0
        """Slot references handed to a subscription so far."""
        self._handlers: dict[int, Handler] = {}
        self._lock = threading.Lock()
        self._closed = False
        self._uid = os.getuid()
        self._inbox = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        self._inbox.setsockopt(socket.SOL_SOCKET, socket.SO_PASSCRED, 1)  # who sent each one
        self._inbox.bind(self.address)
        self._outbox = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        self._outbox.setblocking(False)  # a full queue makes the publisher use Zenoh instead
        self._thread = threading.Thread(target=self._answer, name="cyborg-doorbell",
                                        daemon=True)
        self._thread.start()

    # ------------------------------------------------------------------ receiving
    def register(self, entity_id: int, handler: Handler) -> None:
        """Hand datagrams for subscription ``entity_id`` to ``handler``, on the doorbell thread."""
        with self._lock:
            self._handlers[entity_id] = handler

    def unregister(self, entity_id: int) -> None:
        """Drop the handler of ``entity_id``; its later datagrams are ignored."""
        with self._lock:
            self._handlers.pop(entity_id, None)

    def _answer(self) -> None:
        space = socket.CMSG_SPACE(_CREDENTIALS.size)
        while True:
            try:
                datagram, ancillary, _flags, _address = self._inbox.recvmsg(_MAX_DATAGRAM, space)
            except OSError:  # closed under a handler that outlived close()'s wait
                return
            if self._closed:
                return
            uid = sender_uid(ancillary)
            if uid is not None and uid != self._uid:
                self._drop("doorbell: datagram from another user", f"uid {uid}")
                continue
            try:
                entity_id, attachment, reference = decode(datagram)
            except ValueError as exc:
                self._drop("doorbell: malformed datagram", str(exc))
                continue
            with self._lock:
                handler = self._handlers.get(entity_id)
            if handler is None:  # a subscription destroyed while its reference was on the way
                continue
            self.answered += 1
            try:
                handler(attachment, reference)
            except Exception:  # a handler counts its own bad input; this is a defect
                log.exception("doorbell handler of entity %d raised", entity_id)

    # ------------------------------------------------------------------ ringing
    def ring(self, readers: Iterable[tuple[str, int]], attachment: bytes,
             reference: bytes) -> bool:
        """Send the reference to each (session id, entity id); False if any could not be rung."""
        delivered = True
        for zid, entity_id in readers:
            try:
                self._outbox.sendto(encode(entity_id, attachment, reference),
                                    doorbell_address(self.domain, zid))
            except OSError:  # no such doorbell, or its queue is full
                delivered = False
        return delivered

    # ------------------------------------------------------------------ lifetime
    def close(self) -> None:
        """Stop the thread (after the handler running now) and close both sockets."""
        if self._closed:
            return
        self._closed = True
        with socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM) as waker:
            waker.setblocking(False)
            with contextlib.suppress(OSError):  # a full queue: the thread reads on, sees closed
                waker.sendto(_STOP, self.address)
        if threading.current_thread() is not self._thread:
            self._thread.join(2.0)
        self._inbox.close()
        self._outbox.close()
