"""rosbag2's own description of a recording: the ``rosbag2`` metadata record and ``metadata.yaml``.

``ros2 bag`` writes, in every MCAP file it closes, a metadata record named ``rosbag2`` whose
key ``serialized_metadata`` holds the bag's metadata as YAML, and beside the files of a bag
folder the same YAML as ``metadata.yaml``. Tools read them for a recording's topics, counts and
times without reading its messages (``ros2 bag info``; rosbags opens a folder by its
``metadata.yaml``). cyborg writes both in bag metadata version 9 (Jazzy's):

.. code-block:: yaml

    rosbag2_bagfile_information:
      version: 9
      storage_identifier: mcap
      duration: {nanoseconds: N}              # first message's log time to the last's
      starting_time: {nanoseconds_since_epoch: N}
      message_count: N
      topics_with_message_count:
      - topic_metadata: {name, type, serialization_format: cdr,
                         offered_qos_profiles: [...], type_description_hash: RIHS01_...}
        message_count: N
      compression_format: ''                  # MCAP compresses chunks inside the file
      compression_mode: ''
      relative_file_paths: [run_0.mcap, ...]
      files:
      - {path: run_0.mcap, starting_time: ..., duration: ..., message_count: N}
      custom_data: {cyborg_version: ..., ...} # the recording's ``cyborg`` metadata
      ros_distro: ''                          # not recorded by a ROS distribution

A file's record describes that file alone; a split recording's ``metadata.yaml`` describes
every file of it (:func:`bag_information` of all their :class:`FileSummary`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import yaml

from cyborg.record import layout

VERSION = 9
"""The bag metadata version written (rosbag2 on Jazzy and later)."""
RECORD_NAME = "rosbag2"
"""The MCAP metadata record rosbag2 writes."""
RECORD_KEY = "serialized_metadata"
"""Its one key: the YAML."""
FOLDER_FILE = "metadata.yaml"
"""The bag folder's description, beside its files."""
STORAGE = "mcap"


@dataclass
class TopicCount:
    """One topic of a file: what rosbag2 says of it, and its messages in the file."""

    name: str
    type_name: str
    offered_qos_profiles: str
    """The YAML sequence of the channel's ``offered_qos_profiles`` metadata."""
    type_hash: str
    count: int = 0


@dataclass
class FileSummary:
    """One file of a recording: its name in the folder, its time span and its topics."""

    path: str
    start_ns: int = 0
    end_ns: int = 0
    topics: dict[str, TopicCount] = field(default_factory=dict)
    counted: int = 0
    """Messages counted with :meth:`count`."""

    @property
    def message_count(self) -> int:
        """Messages in the file, on every topic."""
        return sum(topic.count for topic in self.topics.values())

    def count(self, topic: TopicCount, log_time: int) -> None:
        """Counts one message of ``topic`` written at ``log_time`` (once per message written)."""
        if not self.counted:
            self.start_ns = self.end_ns = log_time
        elif log_time < self.start_ns:
            self.start_ns = log_time
        elif log_time > self.end_ns:
            self.end_ns = log_time
        topic.count += 1
        self.counted += 1


def _span(start_ns: int, end_ns: int) -> dict[str, dict[str, int]]:
    return {"starting_time": {"nanoseconds_since_epoch": start_ns},
            "duration": {"nanoseconds": max(end_ns - start_ns, 0)}}


def bag_information(files: list[FileSummary], custom_data: dict[str, str] | None = None
                    ) -> dict[str, object]:
    """The ``rosbag2_bagfile_information`` of ``files`` (one file, or every file of a split)."""
    counted = [item for item in files if item.message_count]
    start = min((item.start_ns for item in counted), default=0)
    end = max((item.end_ns for item in counted), default=0)
    topics: dict[str, TopicCount] = {}
    for item in files:
        for topic in item.topics.values():
            total = topics.setdefault(topic.name, TopicCount(
                topic.name, topic.type_name, topic.offered_qos_profiles, topic.type_hash))
            total.count += topic.count
    information: dict[str, object] = {
        "version": VERSION, "storage_identifier": STORAGE, **_span(start, end),
        "message_count": sum(item.message_count for item in files),
        "topics_with_message_count": [
            {"topic_metadata": {
                "name": topic.name, "type": topic.type_name,
                "serialization_format": layout.MESSAGE_ENCODING,
                "offered_qos_profiles": yaml.safe_load(topic.offered_qos_profiles) or [],
                "type_description_hash": topic.type_hash},
             "message_count": topic.count} for topic in topics.values()],
        "compression_format": "", "compression_mode": "",
        "relative_file_paths": [item.path for item in files],
        "files": [{"path": item.path, **_span(item.start_ns, item.end_ns),
                   "message_count": item.message_count} for item in files],
        "custom_data": dict(custom_data or {}),
        "ros_distro": ""}
    return {"rosbag2_bagfile_information": information}


def serialized(files: list[FileSummary], custom_data: dict[str, str] | None = None) -> str:
    """:func:`bag_information` as the YAML text rosbag2 writes."""
    text: str = yaml.safe_dump(bag_information(files, custom_data), sort_keys=False)
    return text


def write_folder_metadata(folder: Path, files: list[FileSummary],
                          custom_data: dict[str, str] | None = None) -> Path:
    """Writes ``folder/metadata.yaml`` describing ``files``; its path."""
    target = folder / FOLDER_FILE
    target.write_text(serialized(files, custom_data), encoding="utf-8")
    return target
