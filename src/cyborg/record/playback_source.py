"""Recordings to play: what ``cyborg play`` is given, opened by its kind.

:func:`open_recording` returns a :class:`~cyborg.record.recorded.Recording`:

* an MCAP file (``cyborg record``'s, ``ros2 bag``'s, anyone's with ``cdr`` messages and
  ``ros2msg`` schemas) is read by :mod:`cyborg.record.mcap_recording`, so a file cut by
  ``kill -9`` or a power loss plays up to its last whole chunk (``Recording.cut`` says where
  it was cut);
* a ROS 1 bag (``.bag``) or a ROS 2 bag (a folder with ``metadata.yaml``, or a ``.db3`` file in
  one) is read with rosbags' ``AnyReader`` (:mod:`cyborg.record.bag_recording`).

Every message comes as a :class:`~cyborg.record.recorded.Played`: topic, log time (ns) and the
CDR bytes, encapsulation header included, exactly as recorded (ROS 1 messages are converted,
see the bag module). A topic whose type the bus does not know is made known from the
recording's own definition (:meth:`cyborg.bus.MessageTypes.add_definition`); a topic that
still cannot be played (another message encoding, a definition that does not parse) is left
out and named in ``Recording.skipped`` with the reason. A file that is no recording (empty, a
text file, a ROS 1 bag or an SQLite file named ``.mcap``) raises :class:`RecordingError`
naming the file and what it is.
"""

from __future__ import annotations

from pathlib import Path

from cyborg.bus import MessageTypes
from cyborg.record.bag_recording import BagRecording
from cyborg.record.mcap_recording import McapRecording
from cyborg.record.recorded import Played, PlayedTopic, Recording, RecordingError

__all__ = ["Played", "PlayedTopic", "Recording", "RecordingError", "open_recording"]


def open_recording(path: Path, types: MessageTypes) -> Recording:
    """Opens ``path`` to play it on a bus whose types are ``types``; see the module.

    Raises :class:`RecordingError` naming the file for one that cannot be played.
    """
    if not path.exists():
        raise RecordingError(f"{path}: no such file or folder")
    if path.is_dir() or path.suffix in (".bag", ".db3"):
        return BagRecording.open(path, types)
    return McapRecording.open(path, types)
