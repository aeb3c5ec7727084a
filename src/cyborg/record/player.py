"""The player on the bus: a recording published again with its timing, ``/clock`` and latches.

A :class:`Player` is one bus node (``player``, :mod:`cyborg.interfaces.player`) that publishes
the messages of a :class:`~cyborg.record.playback_source.Recording` on their topics:

* **as recorded:** each message's CDR bytes are sent as they are
  (:meth:`~cyborg.bus.raw.RawPublisher.publish_raw`), never decoded and encoded again;
* **with their timing:** message *i* is due at ``t0 + (log_time_i - log_time_0) / rate`` on
  the monotonic clock, so a late message makes no later one late (errors do not add up);
  ``rate`` 2 plays twice as fast;
* **latched again:** a topic recorded from a transient-local publisher is published
  transient-local, so a subscriber that comes late (a monitor opened later) still gets the map;
* **with ``/clock``:** while playing, ``/clock`` (``rosgraph_msgs/Clock``) carries the
  recording's time at the position (its log time), every :data:`CLOCK_PERIOD` seconds and with
  every stepped message, so nodes with ``use_sim_time`` follow the recording. A recording that
  holds ``/clock`` itself (a simulator's) plays that one instead: its time is the one the
  recorded messages' stamps speak of;
* **from a start:** ``start`` seconds into the recording; the latched topics' last messages
  before it are published first, so the map is there at once. A seek does the same and more:
  every other topic's last message of the :data:`RECENT` seconds before the target goes out
  too, so a timeline that seeks while paused shows the state at that time (the robot where it
  was, the tree's last tick), not what the other timeline left;
* **paused, stepped, sought:** :meth:`Player.set_paused`, :meth:`Player.step` (one message,
  then paused), :meth:`Player.seek` (to seconds from the start), and the services
  ``<ns>/player/pause`` (SetBool), ``<ns>/player/step`` (Trigger) and ``<ns>/player/seek``
  (cyborg_msgs/Seek) for a timeline elsewhere; its state goes out latched on
  ``<ns>/player/state`` (cyborg_msgs/PlayerState);
* **looping**, when asked: from the start again after the last message.

Messages are published from the player's own thread, one at a time, in log-time order.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from fnmatch import fnmatchcase

from cyborg.bus import Node, Qos
from cyborg.bus.clock import CLOCK_TOPIC
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import PlayerState
from cyborg.bus.msgs.cyborg_msgs.srv import Seek_Request, Seek_Response
from cyborg.bus.msgs.rosgraph_msgs.msg import Clock
from cyborg.bus.msgs.std_srvs.srv import (
    SetBool_Request,
    SetBool_Response,
    Trigger_Request,
    Trigger_Response,
)
from cyborg.bus.raw import RawPublisher
from cyborg.interfaces import player as contract
from cyborg.interfaces import robot
from cyborg.record.recorded import Played, Recording

log = logging.getLogger(__name__)

CLOCK_PERIOD = 0.01
"""Wall seconds between two ``/clock`` messages while playing (100 Hz, as smooth as a
simulator's steps)."""
QUEUE_DEPTH = 100
"""History depth of a played topic that was not latched."""
RECENT = 2.0
"""Seconds before a seek's target in which each topic's last message is published again."""

Published = Callable[[Played, float, float], object]
"""Told of each message played: the message, when it was due and when it went out (monotonic
seconds)."""


def topic_filter(topics: list[str], exclude: list[str]) -> Callable[[str], bool]:
    """Which topics play: those named (all when none is), less those matching ``exclude``."""
    named = frozenset(topics)
    return lambda topic: ((not named or topic in named)
                          and not any(fnmatchcase(topic, pattern) for pattern in exclude))


@dataclass
class PlayStats:
    """What the player has done; read from any thread."""

    messages: int = 0
    loops: int = 0
    topics: dict[str, int] = field(default_factory=dict)
    """Messages published, by topic."""
    failed: dict[str, str] = field(default_factory=dict)
    """Topics whose messages could not be published, with the last reason."""


class Player:
    """Plays ``recording`` on ``node``'s bus; see the module. Stop it with :meth:`close`.

    ``rate`` (> 0) scales the recorded pace; ``start`` is seconds from the recording's first
    message (0 to its duration); ``accept`` chooses topics by name (all by default);
    ``paused`` starts paused (step or resume to go on); ``on_published`` is told of each
    message. ValueError names the argument that is out of range.
    """

    def __init__(self, node: Node, recording: Recording, *, rate: float = 1.0,
                 start: float = 0.0, loop: bool = False, paused: bool = False,
                 accept: Callable[[str], bool] = lambda topic: True,
                 on_published: Published | None = None) -> None:
        if not rate > 0:
            raise ValueError(f"rate: {rate} is not a speed; give a number above 0")
        if not 0 <= start <= recording.duration:
            raise ValueError(f"start: {start} s is outside the recording (0 to "
                             f"{recording.duration:.3f} s)")
        self.node, self.recording = node, recording
        self.rate, self.loop, self.paused = float(rate), loop, paused
        self.on_published = on_published
        self.stats = PlayStats()
        self.finished = False
        self.topics = {name: topic for name, topic in recording.topics.items() if accept(name)}
        self.own_clock = CLOCK_TOPIC not in self.topics
        self._publishers: dict[str, RawPublisher] = {}
        for name, topic in sorted(self.topics.items()):
            qos = Qos.latched(1) if topic.latched else Qos(depth=QUEUE_DEPTH)
            self._publishers[name] = node.create_raw_publisher(name, topic.type_name, qos)
        self._clock = robot.CLOCK.publisher(node) if self.own_clock else None
        self._state = contract.STATE.publisher(node)
        self._changed = threading.Condition()
        self._position = recording.start_ns + int(start * 1e9)
        self._seek_to: int | None = self._position
        self._sought = False  # the next reposition is a seek: the recent state goes out too
        self._steps = 0
        self._anchor = (time.monotonic(), self._position)  # (wall, recording ns) in step
        self._upcoming: Iterator[Played] = iter(())
        self._next: Played | None = None
        self._closed = False
        self._said_state = 0.0
        contract.PAUSE.server(node, self._on_pause)
        contract.SEEK.server(node, self._on_seek)
        contract.STEP.server(node, self._on_step)
        self._thread = threading.Thread(target=self._run, name="player", daemon=True)
        self._thread.start()

    # ------------------------------------------------------------------ where it stands
    @property
    def position(self) -> float:
        """Seconds from the recording's first message to the last one played."""
        return (self._position - self.recording.start_ns) / 1e9

    def state(self) -> PlayerState:
        """The state as ``<ns>/player/state`` carries it."""
        sec, nanosec = divmod(self._position, 1_000_000_000)
        return PlayerState(position=self.position, duration=self.recording.duration,
                           rate=self.rate, paused=self.paused, finished=self.finished,
                           recording_time=Time(sec=sec, nanosec=nanosec),
                           source=str(self.recording.path))

    # ------------------------------------------------------------------ commands
    def set_paused(self, paused: bool) -> None:
        """Pauses (True) or resumes (False) at the current position."""
        with self._changed:
            if paused != self.paused:
                self.paused = paused
                self._anchor = (time.monotonic(), self._position)
                self._said_state = 0.0  # said at once
                self._changed.notify_all()

    def toggle_pause(self) -> None:
        """Pauses a playing player, resumes a paused one (the space key)."""
        self.set_paused(not self.paused)

    def step(self) -> None:
        """Plays the next message at once and stays paused (pauses a playing player first)."""
        with self._changed:
            self.paused = True
            self._steps += 1
            self._said_state = 0.0
            self._changed.notify_all()

    def seek(self, seconds: float) -> None:
        """Goes to ``seconds`` from the start (ValueError outside 0..duration); keeps pausing."""
        if not 0 <= seconds <= self.recording.duration:
            raise ValueError(f"position: {seconds} s is outside the recording (0 to "
                             f"{self.recording.duration:.3f} s)")
        with self._changed:
            self._seek_to = self.recording.start_ns + int(seconds * 1e9)
            self._sought = True
            self._changed.notify_all()

    def wait_finished(self, timeout: float | None = None) -> bool:
        """Waits until the last message was played (never, when looping); False on timeout."""
        with self._changed:
            return self._changed.wait_for(lambda: self.finished or self._closed, timeout)

    def _on_pause(self, request: SetBool_Request) -> SetBool_Response:
        self.set_paused(request.data)
        return SetBool_Response(success=True, message="paused" if self.paused else "playing")

    def _on_seek(self, request: Seek_Request) -> Seek_Response:
        try:
            self.seek(request.position)
        except ValueError as exc:
            return Seek_Response(success=False, message=str(exc))
        return Seek_Response(success=True, message=f"at {request.position:.3f} s")

    def _on_step(self, _request: Trigger_Request) -> Trigger_Response:
        self.step()
        return Trigger_Response(success=True, message="stepped one message; paused")

    # ------------------------------------------------------------------ the playing thread
    def _run(self) -> None:
        try:
            while True:
                due = self._next_due()
                if due is None:
                    return
                self._publish(*due)
        except Exception:  # a defect: say it, and stop playing rather than die silently
            log.exception("the player stopped")
            with self._changed:
                self.finished = True
                self._changed.notify_all()

    def _next_due(self) -> tuple[Played, float] | None:
        """Waits for the next message to be due (or stepped); None once closed."""
        with self._changed:
            while not self._closed:
                if self._seek_to is not None:
                    self._reposition(self._seek_to)
                    continue
                now = time.monotonic()
                if self._next is None and not self.finished:
                    self._next = next(self._upcoming, None)
                    if self._next is None:
                        self._at_end()
                        continue
                if self._steps and not self.finished:
                    self._steps -= 1
                    return self._take(now, now)
                if self.paused or self.finished:
                    self._steps = 0  # a step past the end does nothing
                    self._say_state(now)
                    self._changed.wait(contract.STATE_PERIOD)
                    continue
                upcoming = self._next
                if upcoming is None:  # not finished, so a message was taken: never so
                    continue
                wall, recorded = self._anchor
                due = wall + (upcoming.log_time - recorded) / 1e9 / self.rate
                if due <= now:
                    return self._take(due, now)
                self._tick_clock(now)
                self._changed.wait(min(due - now, CLOCK_PERIOD))
        return None

    def _take(self, due: float, now: float) -> tuple[Played, float]:
        played, self._next = self._next, None
        assert played is not None
        self._position = played.log_time
        if self.paused:
            self._anchor = (now, self._position)
            self._publish_clock(self._position)
        self._say_state(now)
        return played, due

    def _reposition(self, target: int) -> None:
        """Starts over at ``target`` (ns): the latched topics' last values first."""
        self._seek_to = None
        close = getattr(self._upcoming, "close", None)
        if close is not None:
            close()
        self._upcoming = self.recording.messages(target)
        self._next, self._position, self.finished = None, target, False
        self._anchor = (time.monotonic(), target)
        self._publish_clock(target)
        for played in self.recording.latched_before(target):
            if played.topic in self._publishers:
                self._send(played)
        if self._sought:
            self._sought = False
            for played in self._recent_before(target):
                self._send(played)
        self._said_state = 0.0
        self._changed.notify_all()

    def _recent_before(self, target: int) -> list[Played]:
        """Each unlatched topic's last message of the :data:`RECENT` s before ``target``."""
        since = max(self.recording.start_ns, target - int(RECENT * 1e9))
        last: dict[str, Played] = {}
        if since >= target:
            return []
        upcoming = self.recording.messages(since)
        try:
            for played in upcoming:
                if played.log_time >= target:
                    break
                topic = self.topics.get(played.topic)
                if topic is not None and not topic.latched:
                    last[played.topic] = played
        finally:
            close = getattr(upcoming, "close", None)
            if close is not None:
                close()
        return sorted(last.values(), key=lambda played: played.log_time)

    def _at_end(self) -> None:
        if self.loop:
            self.stats.loops += 1
            self._seek_to = self.recording.start_ns
            return
        if not self.finished:
            self.finished = True
            self._position = max(self._position, self.recording.end_ns)
            self._said_state = 0.0
            self._changed.notify_all()

    def _tick_clock(self, now: float) -> None:
        wall, recorded = self._anchor
        self._publish_clock(recorded + int((now - wall) * self.rate * 1e9))
        self._say_state(now)

    def _publish_clock(self, ns: int) -> None:
        if self._clock is not None and not self._closed:
            sec, nanosec = divmod(max(ns, 0), 1_000_000_000)
            self._clock.publish(Clock(clock=Time(sec=sec, nanosec=nanosec)))

    def _say_state(self, now: float) -> None:
        if now - self._said_state >= contract.STATE_PERIOD and not self._closed:
            self._said_state = now
            self._state.publish(self.state())

    def _publish(self, played: Played, due: float) -> None:
        self._send(played)
        if self.on_published is not None:
            self.on_published(played, due, time.monotonic())

    def _send(self, played: Played) -> None:
        publisher = self._publishers.get(played.topic)
        if publisher is None:
            return
        try:
            publisher.publish_raw(played.data)
        except RuntimeError:
            return  # closed meanwhile
        except Exception as exc:  # bytes that are no message of the type: say it, go on
            self.stats.failed[played.topic] = f"{type(exc).__name__}: {exc}"
            return
        self.stats.messages += 1
        self.stats.topics[played.topic] = self.stats.topics.get(played.topic, 0) + 1

    # ------------------------------------------------------------------ end
    def close(self) -> None:
        """Stops playing and leaves the bus (the recording stays open). Safe to call twice."""
        with self._changed:
            if self._closed:
                return
            self._closed = True
            self._changed.notify_all()
        self._thread.join(timeout=10)
        self.node.destroy()
