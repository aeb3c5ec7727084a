"""The file under a recording: whole writes, or a clean stop at the last whole one.

The MCAP writer hands its stream whole records (a chunk, its message indexes, a metadata
record) one ``write`` at a time. :class:`GuardedStream` passes each on to the file unbuffered,
so what the writer has written is with the operating system at once (a killed recorder loses
only what it had not handed over), and remembers where the last complete write ended. When a
write fails — a full disk (``ENOSPC``), a quota, an I/O error — the partial write is cut off
again, so the file ends on a record boundary, and :class:`StorageError` says what happened:
the recording stops there with a file that :mod:`cyborg.record.completion` can finish.

:meth:`GuardedStream.sync` brings what was written to the disk (``fsync``) on a thread of its
own, so the writer goes on writing into the operating system's cache while the disk catches
up: a camera's stream is faster than many disks for a while, and a writer that waited for
each sync would drop frames that the cache could have taken.
"""

from __future__ import annotations

import contextlib
import errno
import os
import threading
from pathlib import Path
from typing import BinaryIO

REASONS = {errno.ENOSPC: "the disk is full", errno.EDQUOT: "the disk quota is used up",
           errno.EFBIG: "the file is larger than the file system allows",
           errno.EIO: "an input/output error"}
"""What a failed write is called in the message, by errno."""


class StorageError(OSError):
    """A write to a recording failed; the message names the file and the reason."""


class GuardedStream:
    """A binary file opened for a recording; see the module. ``raw`` defaults to ``path``'s."""

    def __init__(self, path: Path, raw: BinaryIO | None = None) -> None:
        self.path = path
        self._file: BinaryIO = raw if raw is not None else open(path, "xb", buffering=0)  # noqa: SIM115
        self.good = 0
        """Bytes of whole writes: the file's length after the last complete write."""
        self.failed: StorageError | None = None
        self._sync_wanted = threading.Event()
        self._syncer: threading.Thread | None = None
        self._closing = False

    def write(self, data: bytes | bytearray | memoryview) -> int:
        """Writes all of ``data`` or raises :class:`StorageError` with the file cut back."""
        if self.failed is not None:
            raise self.failed
        view = memoryview(data).cast("B")
        done = 0
        try:
            while done < len(view):
                written = self._file.write(view[done:])
                if not written:
                    raise OSError(errno.EIO, "the file took no bytes")
                done += written
        except OSError as exc:
            self._cut_back()
            reason = REASONS.get(exc.errno or 0, exc.strerror or str(exc))
            self.failed = StorageError(f"{self.path}: {reason}; the recording stopped after "
                                       f"{self.good} bytes")
            self.failed.errno = exc.errno
            raise self.failed from exc
        self.good += done
        return done

    def _cut_back(self) -> None:
        try:
            self._file.truncate(self.good)
            self._file.seek(self.good)
        except OSError:
            pass  # the file then ends in a partial record, which a scan stops before

    def tell(self) -> int:
        """The position the next write goes to (the MCAP writer asks for chunk offsets)."""
        return self.good

    def flush(self) -> None:
        """Nothing is buffered here; present because the MCAP writer calls it."""

    def sync(self) -> None:
        """Starts bringing what was written to the disk (``fsync``), so power loss keeps it.

        The sync runs on the stream's own thread and this returns at once; one asked for while
        another runs starts as soon as that one is done.
        """
        if self.failed is not None or self._closing:
            return
        if self._syncer is None:
            self._syncer = threading.Thread(target=self._sync_when_asked, daemon=True,
                                            name=f"sync {self.path.name}")
            self._syncer.start()
        self._sync_wanted.set()

    def _sync_when_asked(self) -> None:
        while True:
            self._sync_wanted.wait()
            self._sync_wanted.clear()
            if self._closing:
                return
            # not a real file (a test's), or a file system without fsync: nothing to wait for
            with contextlib.suppress(OSError, ValueError):
                os.fsync(self._file.fileno())

    def close(self) -> None:
        """Closes the file, once a sync that is running has finished."""
        self._closing = True
        if self._syncer is not None:
            self._sync_wanted.set()
            self._syncer.join()
        self._file.close()
