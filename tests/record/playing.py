"""Helpers of the player's tests: a small recording made with the recorder, and a listener."""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from cyborg.bus import BusConfig, Context, Node, Qos
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.bus.raw import RawMessage
from cyborg.record.recorder import Recorder
from cyborg.record.selection import TopicSelection
from cyborg.record.split import RecordingFiles
from tests.bus.bus_peer import wait_for

CHATTER = 20
"""Messages on /chatter in :func:`record_run`, 50 ms apart."""
SPACING = 0.05


def record_run(path: Path) -> None:
    """Records a latched /map (published before the recording starts) and /chatter."""
    with Context(BusConfig.isolated()) as bus:
        talker = Node("talker", context=bus)
        latched = talker.create_publisher("/map", String, Qos.latched())
        latched.publish(String(data="the map"))
        chatter = talker.create_publisher("/chatter", String)
        recorder = Recorder(Node("recorder", context=bus), RecordingFiles(path, bus.types),
                            TopicSelection.of())
        assert wait_for(lambda: recorder.stats.topics.get("/map") == 1, 20)
        assert wait_for(lambda: "/chatter" in recorder.stats.topics, 20)
        start = time.monotonic()
        for number in range(CHATTER):
            time.sleep(max(0.0, start + number * SPACING - time.monotonic()))
            chatter.publish(String(data=f"message {number}"))
        assert wait_for(lambda: recorder.stats.messages == CHATTER + 1, 20)
        recorder.close()


@dataclass
class Listener:
    """Raw subscriptions on a node: every message's bytes and arrival, by topic."""

    node: Node
    got: dict[str, list[RawMessage]] = field(default_factory=dict)
    lock: threading.Lock = field(default_factory=threading.Lock)

    def listen(self, topic: str, type_name: str, *, latched: bool = False) -> None:
        """Subscribes to ``topic`` (transient-local when ``latched``)."""
        self.got.setdefault(topic, [])
        qos = Qos.latched(1) if latched else Qos(depth=1000)
        self.node.create_raw_subscription(topic, type_name, lambda raw: self._add(topic, raw),
                                          qos)

    def _add(self, topic: str, raw: RawMessage) -> None:
        with self.lock:
            self.got[topic].append(raw)

    def data(self, topic: str) -> list[bytes]:
        """The bytes received on ``topic`` so far."""
        with self.lock:
            return [raw.data for raw in self.got[topic]]
