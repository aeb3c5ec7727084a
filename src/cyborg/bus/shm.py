"""Large messages between processes of one machine, through shared-memory slots.

A publisher owns a few *slots*: files in ``/dev/shm``, each mapped into memory. To
send, it serialises the message straight into a free slot (the one copy the transfer costs) and
sends a :class:`SlotRef` — path, generation, length — to the subscribers (by
:mod:`cyborg.bus.doorbell`, or over Zenoh). A subscriber maps the slot
read-only and deserialises in place: numpy fields of the message are views on the shared memory.

Who may write a slot is decided by ``flock`` locks:

* the writer takes an exclusive lock while it fills a slot and releases it before announcing;
* a reader process takes a shared lock before reading and holds it as long as any view made
  from the slot is alive (a ``weakref.finalize`` on each lease array counts them down);
* the writer skips slots it cannot lock and makes new ones up to ``max_slots``; when every slot
  is leased, :meth:`SlotWriter.write` returns ``None`` and the caller sends the bytes inline.

A slot written less than ``REUSE_GRACE`` seconds ago is not reused even when unlocked: its
readers may not have taken their lock yet (the reference is still on its way), so a burst of
messages gets fresh slots instead of overwriting each other. A reader that still finds a newer
generation in the slot (a reader slower than the grace) drops the frame; the caller counts
it. Locks vanish with the process that
held them, so a crashed reader never blocks a writer, and writers remove slot files of dead
processes when they start.

A slot reference is input like any other: any process that can reach the doorbell or Zenoh can
send one, and any local user can put files in ``/dev/shm``. A reader therefore opens a slot
without ever blocking (``O_NONBLOCK``, ``O_NOFOLLOW``) and maps it only if ``fstat`` shows a
regular file owned by this user and at most ``MAX_SLOT_SIZE`` bytes long (:func:`open_slot`);
a FIFO, a device, a socket, a link, someone else's file or a huge one is refused with
:class:`SlotRejectedError`. No call on the way can wait, so a reference cannot park the
thread that receives it.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import mmap
import os
import re
import secrets
import stat
import struct
import tempfile
import threading
import time
import weakref
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

SHM_DIR = Path("/dev/shm") if Path("/dev/shm").is_dir() else Path(tempfile.gettempdir())
PREFIX = "cyborg-shm-"
_HEADER = struct.Struct("<QQ")  # generation, payload length
_REF = struct.Struct("<QQH")  # generation, length, path length; then the path
_GRANULE = 1 << 20
_OWNER = re.compile(rf"^{re.escape(PREFIX)}(\d+)-")
_SLOT_START = f"{SHM_DIR}{os.sep}{PREFIX}"  # how every slot's path begins


@dataclass(frozen=True)
class SlotRef:
    """Where a message lies: which slot file, which generation of it, how many bytes."""

    path: str
    generation: int
    length: int

    def encode(self) -> bytes:
        """The reference as bytes, as :meth:`decode` reads it."""
        raw = self.path.encode()
        return _REF.pack(self.generation, self.length, len(raw)) + raw

    @classmethod
    def decode(cls, data: bytes) -> SlotRef:
        """Parse a reference; ValueError for anything that is not one of ours."""
        if len(data) < _REF.size:
            raise ValueError("slot reference too short")
        generation, length, path_length = _REF.unpack_from(data)
        path = data[_REF.size:].decode()
        name = path[len(_SLOT_START) - len(PREFIX):]  # string checks: Path is slow when cold
        if len(path) != path_length or not path.startswith(_SLOT_START) or "/" in name \
                or "\0" in name:
            raise ValueError("not a cyborg shared-memory slot reference")
        return cls(path, generation, length)


MAX_SLOT_SIZE = 1 << 30
"""The largest slot file, header included, that a reader maps; a writer sends a message that
would need a larger one inline instead."""


class SlotRejectedError(Exception):
    """A slot reference names something that is not one of this user's slots.

    That is a FIFO, device, socket or directory, a symbolic link, another user's file, or a file
    too short or too big. Nothing was opened that could block; the message is dropped.
    """


_KINDS = {stat.S_IFIFO: "FIFO", stat.S_IFCHR: "character device", stat.S_IFBLK: "block device",
          stat.S_IFSOCK: "socket", stat.S_IFDIR: "directory", stat.S_IFLNK: "symbolic link"}
_OPEN_FLAGS = os.O_RDONLY | os.O_NONBLOCK | os.O_NOFOLLOW | os.O_CLOEXEC


def open_slot(path: str) -> tuple[int, os.stat_result]:
    """Open a slot file read-only without ever blocking; (descriptor, its ``fstat``).

    ``O_NONBLOCK`` makes opening a FIFO return at once instead of waiting for a writer, and
    ``O_NOFOLLOW`` refuses a symbolic link; ``fstat`` on the descriptor (not the path, which
    could be swapped meanwhile) then checks what was opened. Raises
    :class:`SlotRejectedError` for anything but a regular file of this user of a slot's size,
    and ``OSError`` (e.g. ``FileNotFoundError``) for a slot that is gone.
    """
    try:
        fd = os.open(path, _OPEN_FLAGS)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise SlotRejectedError(f"{path} is a symbolic link") from None
        if exc.errno in (errno.EACCES, errno.EPERM, errno.ENXIO, errno.ENODEV):
            raise SlotRejectedError(
                f"{path} cannot be read as a slot ({exc.strerror})") from None
        raise
    try:
        info = os.fstat(fd)
        problem = _problem(info)
        if problem:
            raise SlotRejectedError(f"{path} is {problem}")
    except BaseException:
        os.close(fd)
        raise
    return fd, info


def _problem(info: os.stat_result) -> str:
    """What makes a file unfit to be mapped as a slot; empty if nothing."""
    kind = stat.S_IFMT(info.st_mode)
    if kind != stat.S_IFREG:
        return f"a {_KINDS.get(kind, 'special file')}, not a regular file"
    if info.st_uid != os.geteuid():
        return f"owned by uid {info.st_uid}, not by this user (uid {os.geteuid()})"
    if info.st_size < _HEADER.size:
        return f"{info.st_size} bytes long, too short for a slot"
    if info.st_size > MAX_SLOT_SIZE:
        return f"{info.st_size} bytes long, more than a slot may be ({MAX_SLOT_SIZE})"
    return ""


REUSE_GRACE = 0.02
"""Seconds a written slot is left alone for its readers to lock it (a 30 Hz camera's slot is
reused at its next frame; a burst spreads over several slots)."""


class _Slot:
    def __init__(self, path: Path, capacity: int) -> None:
        self.path = path
        self.capacity = capacity
        self.written_at = -float("inf")
        self.fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o600)
        os.ftruncate(self.fd, _HEADER.size + capacity)
        self.map = mmap.mmap(self.fd, _HEADER.size + capacity)

    def try_lock(self) -> bool:
        try:
            fcntl.flock(self.fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            return False
        return True

    def unlock(self) -> None:
        fcntl.flock(self.fd, fcntl.LOCK_UN)

    def close(self) -> None:
        self.path.unlink(missing_ok=True)
        with contextlib.suppress(BufferError):  # a view still lives here: the GC unmaps it
            self.map.close()
        os.close(self.fd)


class SlotWriter:
    """One publisher's slots, reused so that their pages stay in the CPU cache.

    The slot written last is reused first while no reader holds it; a leased slot, or one
    written within ``reuse_grace`` seconds (default ``REUSE_GRACE``), is skipped, and a new one
    is made (up to ``max_slots``) when all are. Creating a writer removes stale slot files.
    """

    def __init__(self, max_slots: int = 16, reuse_grace: float = REUSE_GRACE) -> None:
        self.max_slots = max_slots
        self.reuse_grace = reuse_grace
        self._slots: list[_Slot] = []
        self._generation = 0
        self._tag = f"{PREFIX}{os.getpid()}-{secrets.token_hex(4)}"
        self._count = 0
        remove_stale_slots()

    def write(self, length: int, fill: Callable[[memoryview], object]) -> SlotRef | None:
        """Fill ``length`` bytes of a free slot with ``fill(view)``; the reference to send.

        Returns None if no slot is free, or if the message is too big for a slot readers accept
        (``MAX_SLOT_SIZE``).
        """
        if _HEADER.size + _capacity(length) > MAX_SLOT_SIZE:
            return None
        slot = self._free_slot(length)
        if slot is None:
            return None
        try:
            self._generation += 1
            _HEADER.pack_into(slot.map, 0, self._generation, length)
            with memoryview(slot.map) as whole, whole[_HEADER.size:][:length] as view:
                fill(view)
            slot.written_at = time.monotonic()
        finally:
            slot.unlock()
        return SlotRef(str(slot.path), self._generation, length)

    def _free_slot(self, length: int) -> _Slot | None:
        recent = time.monotonic() - self.reuse_grace
        for index, slot in enumerate(self._slots):  # most recently written first
            if slot.written_at < recent and slot.try_lock():
                if slot.capacity < length:  # too small: replace it with a bigger one
                    slot.unlock()
                    slot.close()
                    slot = self._new_slot(length)
                    slot.try_lock()
                self._slots[index:index + 1] = []
                self._slots.insert(0, slot)
                return slot
        if len(self._slots) >= self.max_slots:
            return None
        slot = self._new_slot(length)
        slot.try_lock()
        self._slots.insert(0, slot)
        return slot

    def _new_slot(self, length: int) -> _Slot:
        self._count += 1
        return _Slot(SHM_DIR / f"{self._tag}-{self._count}", _capacity(length))

    def close(self) -> None:
        """Remove the slot files; readers holding views keep their mappings."""
        for slot in self._slots:
            slot.close()
        self._slots.clear()


def _capacity(length: int) -> int:
    """A slot's payload capacity for a message of ``length`` bytes: whole granules."""
    return -(-length // _GRANULE) * _GRANULE


class _MappedSlot:
    """A slot as a reader sees it: one descriptor, one read-only mapping, a counted lease.

    ``flock`` locks belong to an open file, so one shared lock per slot serves every lease this
    process holds on it: the first lease takes it, the last one to be collected releases it.
    The mapping is made through a descriptor of its own: mmap keeps a duplicate of the
    descriptor it maps, and that duplicate would otherwise hold the lock as long as the mapping.
    Both are opened with :func:`open_slot` and must be the same file.
    """

    def __init__(self, path: str) -> None:
        self.fd, first = open_slot(path)
        try:
            mapping_fd, second = open_slot(path)
            try:
                if (second.st_dev, second.st_ino) != (first.st_dev, first.st_ino):
                    raise SlotRejectedError(f"{path} was replaced while it was being opened")
                self.map = mmap.mmap(mapping_fd, second.st_size, prot=mmap.PROT_READ)
            finally:
                os.close(mapping_fd)
        except BaseException:
            os.close(self.fd)
            raise
        self.leases = 0
        self.retired = False  # evicted from the cache: close once the last lease ends
        self._lock = threading.Lock()

    def lease(self, ref: SlotRef) -> np.ndarray | None:
        with self._lock:
            if self.leases == 0:
                try:
                    fcntl.flock(self.fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
                except BlockingIOError:  # the writer is filling it again
                    return None
            self.leases += 1
        generation, length = _HEADER.unpack_from(self.map, 0)
        fits = length <= len(self.map) - _HEADER.size
        if generation != ref.generation or length != ref.length or not fits:
            self._release()
            return None
        view = np.frombuffer(self.map, np.uint8, count=length, offset=_HEADER.size)
        weakref.finalize(view, self._release)
        return view

    def _release(self) -> None:
        with self._lock:
            self.leases -= 1
            if self.leases:
                return
            if self.retired:
                os.close(self.fd)
                self.fd = -1
            else:
                fcntl.flock(self.fd, fcntl.LOCK_UN)

    def retire(self) -> None:
        with self._lock:
            self.retired = True
            if self.leases == 0 and self.fd >= 0:
                os.close(self.fd)
                self.fd = -1


class SlotReader:
    """Maps publishers' slots (read-only) and leases them for as long as views live.

    The ``cache_size`` slots used last stay mapped; older ones close when their leases end.
    """

    def __init__(self, cache_size: int = 64) -> None:
        self._slots: OrderedDict[str, _MappedSlot] = OrderedDict()
        self._cache_size = cache_size
        self._lock = threading.Lock()

    def read(self, ref: SlotRef) -> np.ndarray | None:
        """A read-only byte array over the message, or None if the slot was reused or gone.

        The slot stays leased (the writer cannot reuse it) until the returned array and every
        view made from it have been garbage-collected. Raises :class:`SlotRejectedError` when
        the reference names something that is not a slot (see :func:`open_slot`).
        """
        try:
            slot = self._slot(ref.path)
        except (OSError, ValueError):  # gone
            return None
        return slot.lease(ref)

    def _slot(self, path: str) -> _MappedSlot:
        with self._lock:
            slot = self._slots.get(path)
            if slot is not None:
                self._slots.move_to_end(path)
                return slot
        opened = _MappedSlot(path)  # outside the lock: a slow open stalls no other reader
        with self._lock:
            slot = self._slots.get(path)
            if slot is not None:  # another thread mapped it meanwhile
                opened.retire()
                return slot
            self._slots[path] = opened
            while len(self._slots) > self._cache_size:
                self._slots.popitem(last=False)[1].retire()
            return opened

    def close(self) -> None:
        """Let go of every slot; each one's file closes once the views leased from it are gone."""
        with self._lock:
            for slot in self._slots.values():
                slot.retire()
            self._slots.clear()


def remove_stale_slots(folder: Path = SHM_DIR) -> int:
    """Delete slot files whose owning process is gone; returns how many."""
    removed = 0
    for path in folder.glob(f"{PREFIX}*"):
        match = _OWNER.match(path.name)
        if match and not _alive(int(match.group(1))):
            path.unlink(missing_ok=True)
            removed += 1
    return removed


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True
