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
"""

from __future__ import annotations

import contextlib
import fcntl
import mmap
import os
import re
import secrets
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
        if len(path) != path_length or not path.startswith(_SLOT_START) or "/" in name:
            raise ValueError("not a cyborg shared-memory slot reference")
        return cls(path, generation, length)


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
    """One publisher's slots. The slot written last is reused first while no reader holds
    it, so its pages are still in the CPU cache; a leased slot, or one written within
    ``REUSE_GRACE``, is skipped, and a new one is made (up to ``max_slots``) when all are."""

    def __init__(self, max_slots: int = 16, reuse_grace: float = REUSE_GRACE) -> None:
        self.max_slots = max_slots
        self.reuse_grace = reuse_grace
        self._slots: list[_Slot] = []
        self._generation = 0
        self._tag = f"{PREFIX}{os.getpid()}-{secrets.token_hex(4)}"
        self._count = 0
        remove_stale_slots()

    def write(self, length: int, fill: Callable[[memoryview], object]) -> SlotRef | None:
        """Fill ``length`` bytes of a free slot with ``fill(view)``; None if none is free."""
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
        capacity = -(-length // _GRANULE) * _GRANULE
        return _Slot(SHM_DIR / f"{self._tag}-{self._count}", capacity)

    def close(self) -> None:
        """Remove the slot files; readers holding views keep their mappings."""
        for slot in self._slots:
            slot.close()
        self._slots.clear()


class _MappedSlot:
    """A slot as a reader sees it: one descriptor, one read-only mapping, a counted lease.

    ``flock`` locks belong to an open file, so one shared lock per slot serves every lease this
    process holds on it: the first lease takes it, the last one to be collected releases it.
    The mapping is made through a descriptor of its own: mmap keeps a duplicate of the
    descriptor it maps, and that duplicate would otherwise hold the lock as long as the mapping.
    """

    def __init__(self, path: str) -> None:
        self.fd = os.open(path, os.O_RDONLY)
        try:
            mapping_fd = os.open(path, os.O_RDONLY)
            try:
                self.map = mmap.mmap(mapping_fd, 0, prot=mmap.PROT_READ)
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
    """Maps publishers' slots (read-only) and leases them for as long as views live."""

    def __init__(self, cache_size: int = 64) -> None:
        self._slots: OrderedDict[str, _MappedSlot] = OrderedDict()
        self._cache_size = cache_size
        self._lock = threading.Lock()

    def read(self, ref: SlotRef) -> np.ndarray | None:
        """A read-only byte array over the message, or None if the slot was reused or gone.

        The slot stays leased (the writer cannot reuse it) until the returned array and every
        view made from it have been garbage-collected.
        """
        try:
            slot = self._slot(ref.path)
        except (OSError, ValueError):  # gone, or empty
            return None
        return slot.lease(ref)

    def _slot(self, path: str) -> _MappedSlot:
        with self._lock:
            slot = self._slots.get(path)
            if slot is None:
                slot = self._slots[path] = _MappedSlot(path)
                while len(self._slots) > self._cache_size:
                    self._slots.popitem(last=False)[1].retire()
            else:
                self._slots.move_to_end(path)
            return slot

    def close(self) -> None:
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
