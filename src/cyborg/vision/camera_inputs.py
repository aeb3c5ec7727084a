"""Which of a camera's streams to wait for: pairing by exact stamp that follows the bus graph.

A detector subscribes to an image topic and, optionally, a depth topic and a right-image topic.
Waiting for a depth map that nobody publishes — a camera playing a video file has none — would
stop detection altogether, so :class:`CameraInputs` waits only for the optional streams that
have a **publisher in the bus graph** now; without one, each image is a frame on its own and
its detections have an unknown distance (NaN), never a made-up one.

A publisher that advertises depth but yields no pair — it sends nothing, or its stamps never
match the images' — is waited for ``patience`` seconds (5) of arriving images. Then the detector
goes on with images alone, and the log says why, once per outage (a warning the first time,
info after): which topic is silent, who publishes it and how many of its messages came. The
same is said when images have arrived for ``patience`` seconds and nothing at all publishes the
depth topic (a video camera, or a topic name with a typo)::

    WARNING /cyborg/detector/detector: images arrive on /cyborg/camera/left/image_raw but
    nothing is published on depth topic /cyborg/camera/depth/depth_registered (5 s without a
    pair): detecting without distance (NaN) until depth pairs with them

=============  ==================================================================================
state          what an image becomes
=============  ==================================================================================
image only     no optional topic has a publisher: a frame at once
pairing        a frame once the published optional streams of its stamp have arrived
starved        pairing gave nothing for ``patience`` s: a frame at once, while the streams are
               still paired on the side; the first complete pair goes back to *pairing*
=============  ==================================================================================

Time comes from an injected monotonic ``clock`` (seconds), so tests move it by hand. Not
thread-safe: a node runs its callbacks one at a time.
"""

from __future__ import annotations

import logging
import time
from collections import Counter
from collections.abc import Callable
from typing import Any

from cyborg.vision.camera_topics import CameraTopics
from cyborg.vision.pairing import ExactPairer

log = logging.getLogger(__name__)

OPTIONAL = ("depth", "right")
"""The streams that may accompany the image, in pairing order."""

_TOPIC = {"depth": "depth topic", "right": "right-image topic"}
_ITEM = {"depth": "a depth map", "right": "a right image"}


class CameraInputs:
    """Turns a camera's messages into frames' message sets (``{"image": ..., "depth": ...}``).

        inputs = CameraInputs(topics, publishers=lambda topic: [...node names...])
        messages = inputs.add("image", stamp, message)   # None: waiting for its partners

    ``publishers(topic)`` names the nodes publishing ``topic`` now (from the bus graph).
    """

    def __init__(self, topics: CameraTopics, publishers: Callable[[str], list[str]], *,
                 clock: Callable[[], float] = time.monotonic, patience: float = 5.0,
                 max_pending: int = 10, name: str = "camera inputs") -> None:
        self.topics, self.publishers, self.clock = topics, publishers, clock
        self.patience, self.max_pending, self.name = patience, max_pending, name
        self.optional = tuple(stream for stream in OPTIONAL if getattr(topics, stream))
        self.streams: tuple[str, ...] = ("image",)
        """The streams paired now: the image, and the optional ones that have a publisher."""
        self.pairer = ExactPairer(self.streams, max_pending)
        self.probe: ExactPairer | None = None
        """While starved: the streams paired on the side, to notice when pairs come back."""
        self.since: float | None = None
        """Clock time of the first image since the last pair (None: none yet)."""
        self.received: Counter[str] = Counter()
        """Messages of each optional stream since the last pair."""
        self.complained = False
        self.heard: set[str] = set()
        """Optional streams whose messages came before the graph showed their publisher (a
        camera that starts publishing at once): paired until the graph catches up."""
        self.shown: set[str] = set()
        """Optional streams the graph has shown a publisher of; from then on it decides."""
        self._warned = False
        self._dropped = 0

    @property
    def dropped(self) -> int:
        """Messages that never became part of a frame; not counted while starved.

        Such as an image overtaken while it waited for its depth map, or a depth map without
        its image.
        """
        return self._dropped + self.pairer.dropped

    @property
    def starved(self) -> bool:
        """Whether images go out alone because the optional streams gave no pair in time."""
        return self.probe is not None

    def add(self, stream: str, stamp: int, message: Any) -> dict[str, Any] | None:
        """One message in; the messages of a frame when this one completes (or is) a frame."""
        if stream in self.optional and stream not in self.shown:
            self.heard.add(stream)  # a message proves a publisher the graph may not show yet
        self._follow_graph()
        if stream != "image":
            if stream not in self.streams:  # its publisher is not in the graph (yet)
                self._dropped += 1
                return None
            self.received[stream] += 1
        expired = stream == "image" and self._waited_too_long()
        if self.probe is not None:
            return self._add_starved(stream, stamp, message)
        complete = self.pairer.add(stream, stamp, message)
        if complete is not None and len(complete) > 1:
            self._paired()
            return complete
        if not expired:
            return complete
        self._complain()
        if complete is not None:  # image only: nothing is published beside the images
            return complete
        self._starve(stamp, message)
        return {"image": message}

    def _waited_too_long(self) -> bool:
        """Images have come for ``patience`` s without a pair (the clock is read per image)."""
        now = self.clock()
        if self.since is None:
            self.since = now
        return bool(self.optional) and now - self.since >= self.patience

    # ------------------------------------------------------------------ states
    def _follow_graph(self) -> None:
        """Pairs exactly the optional streams that have a publisher now.

        Before the graph shows a stream's publisher, a message of it is enough.
        """
        published = {stream for stream in self.optional
                     if self.publishers(getattr(self.topics, stream))}
        self.shown |= published
        self.heard -= published
        wanted = ("image", *(stream for stream in self.optional
                             if stream in published or stream in self.heard))
        if wanted == self.streams:
            return
        log.info("%s: pairing %s by stamp (publishers of %s: %s)", self.name,
                 " + ".join(wanted), ", ".join(self.optional),
                 "; ".join(", ".join(self.publishers(getattr(self.topics, stream))) or "none"
                           for stream in self.optional))
        self._restart(wanted)
        self.complained = False

    def _restart(self, streams: tuple[str, ...]) -> None:
        """Pair ``streams`` from now on; what waited for the old set is dropped."""
        self.pairer.finish()
        self._dropped += self.pairer.dropped
        self.streams, self.pairer, self.probe = streams, ExactPairer(streams,
                                                                     self.max_pending), None
        self.since = None
        self.received.clear()

    def _starve(self, stamp: int, image: Any) -> None:
        """No pair for ``patience`` s: images go on alone, paired on the side (the probe)."""
        self._restart(self.streams)
        self._dropped -= 1  # the image that waited too long goes out alone, not dropped
        self.probe = ExactPairer(self.streams, self.max_pending)
        self.probe.add("image", stamp, image)  # its partners may still come

    def _add_starved(self, stream: str, stamp: int, message: Any) -> dict[str, Any] | None:
        assert self.probe is not None
        complete = self.probe.add(stream, stamp, message)
        if complete is not None:  # pairs again: the probe, with what waits in it, takes over
            self.pairer, self.probe = self.probe, None
            self.pairer.dropped = 0  # images it held went out alone
            self._paired()
            # an image that completes a pair is a frame with depth; an image that came first
            # already went out alone
            return complete if stream == "image" else None
        return {"image": message} if stream == "image" else None

    def _paired(self) -> None:
        if self.complained:
            again = [f"{_TOPIC[stream]} {getattr(self.topics, stream)}"
                     for stream in self.streams[1:]]
            log.info("%s: %s %s again with the images on %s: distances resume", self.name,
                     " and ".join(again), "pairs" if len(again) == 1 else "pair",
                     self.topics.image)
        self.since = None
        self.received.clear()
        self.complained = False

    def _complain(self) -> None:
        """Say once why images go on without depth: a warning the first time, then info."""
        if self.complained:
            return
        self.complained = True
        parts = []
        for stream in self.optional:
            topic = getattr(self.topics, stream)
            publishers = self.publishers(topic)
            if not publishers:
                parts.append(f"nothing is published on {_TOPIC[stream]} {topic}")
                continue
            count = self.received[stream]
            came = f"{count} received, none with an image's stamp" if count else "none received"
            parts.append(f"none paired with {_ITEM[stream]} on {topic} (published by "
                         f"{', '.join(publishers)}; {came})")
        level = logging.INFO if self._warned else logging.WARNING
        self._warned = True
        log.log(level, "%s: images arrive on %s but %s (%g s without a pair): detecting "
                "without distance (NaN) until depth pairs with them", self.name,
                self.topics.image, " and ".join(parts), self.patience)
