"""The recorder on the bus: finds topics in the graph, takes their raw CDR, writes it down.

A :class:`Recorder` is one bus node (``recorder`` by default) that

* looks at the bus graph at once and then every :data:`DISCOVERY_INTERVAL` seconds, so
  topics that appear after the start are recorded from their first message; each topic the
  :class:`~cyborg.record.selection.TopicSelection` accepts gets a raw subscription
  (:meth:`~cyborg.bus.node.Node.create_raw_subscription`): its messages are written as the
  CDR bytes they travelled in, never decoded and encoded again;
* subscribes transient-local where a publisher is latched, so the latched value (the map,
  the tree's structure, the battery) is recorded even when it was published before the start;
* writes each message with the time it was received as its log time and the sender's
  timestamp (from the sample's attachment) as its publish time, on the node's one thread:
  its subscriptions are *batched* (:mod:`cyborg.bus.raw`), so messages wait in their topic's
  queue and are written every :data:`WRITE_INTERVAL` together, in the order they arrived —
  a few thread wake-ups a second instead of one per message, which cost more than the
  writing;
* counts what it could not write: each topic's queue holds :data:`QUEUE_DEPTH` messages
  (:data:`IMAGE_QUEUE_DEPTH` for images) while the writer is busy, and drops the oldest beyond
  that; a gap in a publisher's sequence numbers after the first message received from it is
  a message sent and never written, counted in :attr:`RecordingStats.dropped` (also when the
  bus lost it on the way);
* closes the open chunk at least every second (:mod:`cyborg.record.mcap_file`);
* pauses and resumes: :meth:`Recorder.set_paused`, and the service ``<node>/pause``
  (``std_srvs/srv/SetBool``: true pauses, false resumes), so ``cyborg service call
  /recorder/pause "{data: true}"`` pauses a recording from anywhere; messages that arrive while
  paused are not written;
* stops cleanly on a failed write (a full disk): :attr:`Recorder.failure` says why, and the
  file is finished in place so that it stays readable.

Topics whose type the bus does not know are skipped and listed in
:attr:`RecordingStats.skipped`. A metadata record ``cyborg`` names the cyborg version and
what the caller knows of the run (the map and tree files); the map a simulator publishes
(``map_geometry``) is named too, in a ``cyborg.map`` record, when it is recorded.
"""

from __future__ import annotations

import logging
import threading
import time
from dataclasses import dataclass, field
from importlib.metadata import PackageNotFoundError, version

from cyborg.bus import Durability, Node, Qos
from cyborg.bus.msgs.std_srvs.srv import SetBool, SetBool_Request, SetBool_Response
from cyborg.bus.raw import RawMessage, RawSubscription
from cyborg.bus.wire import EntityKind
from cyborg.interfaces import robot
from cyborg.record import layout
from cyborg.record.guarded_stream import StorageError
from cyborg.record.selection import IMAGE_TYPES, TopicSelection
from cyborg.record.split import RecordingFiles

log = logging.getLogger(__name__)

NAME = "recorder"
"""The recorder's node name; its pause service is ``<namespace>/recorder/pause``."""
DISCOVERY_INTERVAL = 0.5
"""Seconds between two looks at the graph for new topics."""
WRITE_INTERVAL = 0.05
"""Seconds between two writes of what arrived meanwhile (and checks whether the open chunk
is due to be flushed)."""
QUEUE_DEPTH = 1000
"""Messages of a topic that may wait for the writer before the oldest are dropped."""
IMAGE_QUEUE_DEPTH = 30
"""The same for image topics: about a second of a camera, without holding gigabytes."""
CLOSE_WAIT = 5.0
"""Seconds :meth:`Recorder.close` waits for the writer to write what arrived last."""
RUN_METADATA = layout.RUN_METADATA
"""Name of the metadata record that names the version, map and tree of the run."""
MAP_METADATA = layout.MAP_METADATA
"""Name of the metadata record written for each map the recorded simulator published."""


MAP_TYPE = robot.MAP_GEOMETRY.type_name
"""The type of the simulator's map, named in a ``cyborg.map`` metadata record when recorded."""


def _arrival(item: tuple[str, RawMessage]) -> int:
    return item[1].received_ns


def cyborg_version() -> str:
    """The installed cyborg's version, or ``unknown``."""
    try:
        return version("cyborg")
    except PackageNotFoundError:
        return "unknown"


@dataclass
class RecordingStats:
    """What a recording has done so far; read from any thread."""

    messages: int = 0
    bytes: int = 0
    """CDR bytes written (before compression)."""
    topics: dict[str, int] = field(default_factory=dict)
    """Messages written, by topic (every topic subscribed is here, from 0)."""
    skipped: dict[str, str] = field(default_factory=dict)
    """Topics not recorded, with the reason (an unknown type)."""
    paused_drops: int = 0
    """Messages that arrived while paused."""
    dropped: int = 0
    """Messages sent and never written: gaps in a publisher's sequence numbers (the queue was
    full while the writer was busy, or the bus lost them on the way)."""


class Recorder:
    """Records the bus into ``files``; see the module. Stop it with :meth:`close`.

    ``node`` is the recorder's own node (it destroys it when closed); ``run`` adds values to
    the ``cyborg`` metadata record (``map``, ``tree``, ``command``); the version and the start
    time are always there.
    """

    def __init__(self, node: Node, files: RecordingFiles, selection: TopicSelection, *,
                 run: dict[str, str] | None = None) -> None:
        self.node, self.context = node, node.context
        self.files, self.selection = files, selection
        self.stats = RecordingStats()
        self.failure: str | None = None
        self.paused = False
        self._lock = threading.Lock()
        self._discovering = threading.Lock()
        self._types: dict[str, str] = {}
        self._maps: dict[str, str] = {}
        self._sequences: dict[tuple[str, bytes], int] = {}  # (topic, publisher) -> last seen
        self.subscriptions: dict[str, RawSubscription] = {}
        """The raw subscription of each topic recorded."""
        self._arrived: list[tuple[str, RawMessage]] = []  # drained, not yet written
        self._closed = False
        files.add_metadata(RUN_METADATA, {
            "cyborg_version": cyborg_version(),
            "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"), **(run or {})})
        node.create_service(f"{node.name}/pause", SetBool, self._on_pause)
        self.node.create_timer(DISCOVERY_INTERVAL, self.discover)
        self.node.create_timer(WRITE_INTERVAL, self._write_waiting)
        self.discover()

    # ------------------------------------------------------------------ topics
    def discover(self) -> None:
        """Subscribes to every new topic of the graph that the selection accepts."""
        with self._discovering:  # the first look (the caller's thread) may meet the timer's
            self._discover()

    def _discover(self) -> None:
        offered: dict[str, list[tuple[str, str]]] = {}
        for entity in self.context.graph.entities([EntityKind.PUBLISHER]):
            offered.setdefault(entity.topic, []).append((entity.type_name, entity.qos))
        for topic, publishers in sorted(offered.items()):
            if topic in self._types or topic in self.stats.skipped:
                continue
            type_name = sorted(type_name for type_name, _ in publishers)[0]
            if not self.selection.accepts(topic, type_name):
                continue
            if type_name not in self.context.types:
                self.stats.skipped[topic] = f"unknown type {type_name}"
                log.warning("not recording %s: its type %s is not known here", topic,
                            type_name)
                continue
            self._subscribe(topic, type_name, [qos for name, qos in publishers
                                               if name == type_name])

    def _subscribe(self, topic: str, type_name: str, offered: list[str]) -> None:
        latched = any(len(qos.split(":")) > 1 and qos.split(":")[1] == "1" for qos in offered)
        depth = IMAGE_QUEUE_DEPTH if type_name in IMAGE_TYPES else QUEUE_DEPTH
        qos = Qos(durability=Durability.TRANSIENT_LOCAL if latched else Durability.VOLATILE,
                  depth=depth)
        with self._lock:
            if self.failure is not None or self._closed:
                return
            self.files.add_topic(topic, type_name, offered)
            self._types[topic] = type_name
        try:
            arrived = self._arrived
            self.subscriptions[topic] = self.node.create_raw_subscription(
                topic, type_name, lambda raw: arrived.append((topic, raw)), qos, batched=True)
        except RuntimeError:  # the recorder is being closed
            return
        self.stats.topics.setdefault(topic, 0)  # listed once messages can arrive

    @property
    def backlog_peak(self) -> int:
        """The most messages that waited for the writer at once in any topic's queue."""
        return max((sub.backlog_peak for sub in list(self.subscriptions.values())), default=0)

    # ------------------------------------------------------------------ messages
    def _write_waiting(self) -> None:
        """Writes what arrived since the last time, in the order it arrived (node's thread).

        Then closes the open chunk if it is due (:mod:`cyborg.record.mcap_file`).
        """
        for subscription in list(self.subscriptions.values()):
            subscription.drain()  # each message onto self._arrived
        arrived = self._arrived[:]
        self._arrived.clear()
        if len(arrived) > 1:
            arrived.sort(key=_arrival)
        maps: list[tuple[str, bytes]] = []
        with self._lock:
            if self.failure is not None or self._closed:
                return
            try:
                for topic, raw in arrived:
                    if self._write(topic, raw) and self._types[topic] == MAP_TYPE:
                        maps.append((topic, raw.data))
                self.files.flush_if_due()
            except StorageError as exc:
                self._fail(exc)
                return
        for topic, data in maps:
            self._note_map(topic, data)

    def _write(self, topic: str, raw: RawMessage) -> bool:
        """Writes one message (the lock is held) unless paused; counts what went missing."""
        info = raw.info
        if info is not None:
            key = (topic, info.gid)
            last = self._sequences.get(key)
            self._sequences[key] = info.sequence
            if last is not None and info.sequence > last + 1:
                self.stats.dropped += info.sequence - last - 1
        if self.paused:
            self.stats.paused_drops += 1
            return False
        sent = info.timestamp_ns if info is not None else raw.received_ns
        if sent < 0:  # a sender's clock is not checked by the bus; MCAP times are unsigned
            sent = raw.received_ns
        self.files.write(topic, raw.received_ns, sent, raw.data)
        stats = self.stats
        stats.messages += 1
        stats.bytes += len(raw.data)
        stats.topics[topic] = stats.topics.get(topic, 0) + 1
        return True

    def _note_map(self, topic: str, data: bytes) -> None:
        """Names a map the simulator published in a ``cyborg.map`` metadata record."""
        try:
            geometry = self.context.types.deserialize(data, MAP_TYPE)
        except Exception:  # not ours to judge: it is recorded as it came
            return
        if self._maps.get(topic) == geometry.hash:
            return
        self._maps[topic] = geometry.hash
        with self._lock:
            if self.failure is None and not self._closed:
                self.files.add_metadata(MAP_METADATA, {"topic": topic, "source": geometry.source,
                                                       "hash": geometry.hash})

    def _fail(self, exc: StorageError) -> None:
        """A write failed (the lock is held): stop recording, finish the file as it is."""
        self.failure = str(exc)
        log.error("recording stopped: %s", exc)
        self.files.close()

    # ------------------------------------------------------------------ pause
    def set_paused(self, paused: bool) -> None:
        """Pauses (True) or resumes (False) writing; messages meanwhile are not written."""
        if paused != self.paused:
            self.paused = paused
            log.info("recording %s", "paused" if paused else "resumed")

    def toggle_pause(self) -> None:
        """Pauses a running recording, resumes a paused one (``SIGUSR1``, a key)."""
        self.set_paused(not self.paused)

    def _on_pause(self, request: SetBool_Request) -> SetBool_Response:
        self.set_paused(request.data)
        return SetBool_Response(success=True, message="paused" if self.paused else "recording")

    # ------------------------------------------------------------------ end
    def close(self) -> None:
        """Writes what arrived last, leaves the bus and finishes the files. Safe to call twice."""
        if not self._closed and not self.node.destroyed and not self.context.closed:
            if self.node.callbacks.in_thread():
                self._write_waiting()
            else:
                self.node.callbacks.submit(self._write_waiting)
                self.node.callbacks.flush(CLOSE_WAIT)
        self.node.destroy()
        with self._lock:
            if self._closed:
                return
            self._closed = True
            if self.failure is None:
                try:
                    self.files.close()
                except StorageError as exc:
                    self._fail(exc)
