"""The rosbag2 layout of an MCAP file: what ``ros2 bag`` and Foxglove expect to find.

* the header's profile is ``ros2``;
* one schema per message type, named ``pkg/msg/Type``, encoding ``ros2msg``: the type's
  ``.msg`` text followed by each type it uses, once, after a line of 80 ``=`` and
  ``MSG: pkg/Type`` (rosbag2's own form, produced by rosbags' ``generate_msgdef``);
* one channel per topic, message encoding ``cdr``, with the metadata rosbag2 writes:
  ``offered_qos_profiles`` (a YAML sequence, one profile per publisher, policies as strings as
  in bag metadata version 9 and later) and ``topic_type_hash`` (``RIHS01_<hex>``);
* each message's log time is when the recorder received it and its publish time the sender's
  timestamp (from the sample's attachment), as rosbag2 writes ``recv_timestamp`` and
  ``send_timestamp``.

A player and a report read these back with any MCAP reader; nothing here is cyborg's own.
"""

from __future__ import annotations

from cyborg.bus import MessageTypes

PROFILE = "ros2"
"""The MCAP header profile of a ROS 2 recording."""
SCHEMA_ENCODING = "ros2msg"
"""How a schema's data is written: ROS 2 ``.msg`` text with its dependencies."""
MESSAGE_ENCODING = "cdr"
"""How a message's data is written: CDR with its encapsulation header, as on the wire."""
QOS_KEY = "offered_qos_profiles"
"""Channel metadata: the QoS the topic's publishers offered, as rosbag2 writes it."""
TYPE_HASH_KEY = "topic_type_hash"
"""Channel metadata: the RIHS01 hash of the topic's type, as rosbag2 writes it."""
LIBRARY = "cyborg record"
"""The MCAP header's library field, before the version."""
RUN_METADATA = "cyborg"
"""Name of the metadata record that names the version, map and tree of the run (and whose
values are the ``custom_data`` of the rosbag2 metadata, :mod:`cyborg.record.bag_metadata`)."""
MAP_METADATA = "cyborg.map"
"""Name of the metadata record written for each map the recorded simulator published."""

_INFINITE = "{sec: 9223372036, nsec: 854775807}"
_RELIABILITY = {"1": "reliable", "2": "best_effort"}
_DURABILITY = {"1": "transient_local", "2": "volatile"}
_HISTORY = {"1": "keep_last", "2": "keep_all"}
_DEFAULT_DEPTH = 42  # rmw_zenoh's, left out of its QoS strings


def schema_text(types: MessageTypes, type_name: str) -> bytes:
    """The ``ros2msg`` schema data of ``type_name``: its definition and its dependencies'.

    Raises KeyError naming the type when the bus does not know it.
    """
    if type_name not in types:
        raise KeyError(f"unknown message type {type_name!r}")
    text, _digest = types.store.generate_msgdef(type_name, ros_version=2)
    return text.encode()


def qos_profile(qos: str) -> str:
    """One QoS profile of ``offered_qos_profiles`` from an rmw_zenoh QoS string.

    ``qos`` is the last chunk of a publisher's liveliness token (``1:1:1,5:,:,:,,``: fields
    left empty are rmw_zenoh's defaults, reliable, volatile, keep-last 42).
    """
    fields = qos.split(":")
    reliability = _RELIABILITY.get(fields[0] if fields else "", "reliable")
    durability = _DURABILITY.get(fields[1] if len(fields) > 1 else "", "volatile")
    history_depth = fields[2].split(",") if len(fields) > 2 else [""]
    history = _HISTORY.get(history_depth[0], "keep_last")
    depth_text = history_depth[1] if len(history_depth) > 1 else ""
    depth = int(depth_text) if depth_text.isdigit() else _DEFAULT_DEPTH
    return (f"- history: {history}\n  depth: {depth}\n  reliability: {reliability}\n"
            f"  durability: {durability}\n  deadline: {_INFINITE}\n  lifespan: {_INFINITE}\n"
            f"  liveliness: automatic\n  liveliness_lease_duration: {_INFINITE}\n"
            "  avoid_ros_namespace_conventions: false")


def channel_metadata(types: MessageTypes, type_name: str, offered: list[str]) -> dict[str, str]:
    """The metadata of a topic's channel: its publishers' QoS profiles and its type hash.

    ``offered`` holds the rmw_zenoh QoS strings of the topic's publishers (empty when none is
    known: the YAML is then an empty sequence, ``[]``).
    """
    profiles = "\n".join(qos_profile(qos) for qos in offered) if offered else "[]"
    return {QOS_KEY: profiles, TYPE_HASH_KEY: types.hash(type_name)}
