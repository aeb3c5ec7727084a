"""Which topics a recording takes: the ones named, or all but the excluded, images on request.

* No topics named: every topic a publisher offers, as ``ros2 bag record --all`` does, less
  hidden topics (a name part starting with ``_``, such as an action's ``_action/feedback``)
  and images (``sensor_msgs/msg/Image`` and ``CompressedImage``: a camera alone writes
  hundreds of MB a second), unless ``images`` asks for them.
* Topics named: exactly those, images and hidden ones included; a name without a leading
  ``/`` is taken from the root (``pose`` is ``/pose``).
* ``exclude``: glob patterns on the full topic name (``/cyborg/camera/*``), applied last.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from fnmatch import fnmatchcase

IMAGE_TYPES = frozenset({"sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage"})
"""Types left out of a recording of all topics unless images are asked for."""


def absolute(topic: str) -> str:
    """``pose`` -> ``/pose``: topics in the graph, and in a recording, are fully qualified."""
    return topic if topic.startswith("/") else "/" + topic


@dataclass(frozen=True)
class TopicSelection:
    """What to record: ``topics`` (empty: all), ``exclude`` patterns, and whether images go too."""

    topics: frozenset[str] = field(default_factory=frozenset)
    exclude: tuple[str, ...] = ()
    images: bool = False

    @classmethod
    def of(cls, topics: Iterable[str] = (), exclude: Iterable[str] = (), *,
           images: bool = False) -> TopicSelection:
        """A selection from command-line words; raises ValueError naming an empty pattern."""
        patterns = tuple(exclude)
        for pattern in patterns:
            if not pattern.strip():
                raise ValueError("--exclude: an empty pattern would match nothing; give a "
                                 "glob such as '/cyborg/camera/*'")
        return cls(frozenset(absolute(topic) for topic in topics), patterns, images)

    def accepts(self, topic: str, type_name: str) -> bool:
        """Whether ``topic`` (of ``type_name``) is recorded."""
        if any(fnmatchcase(topic, pattern) for pattern in self.exclude):
            return False
        if self.topics:
            return topic in self.topics
        hidden = any(part.startswith("_") for part in topic.split("/"))
        return not hidden and (self.images or type_name not in IMAGE_TYPES)
