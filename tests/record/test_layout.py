"""The rosbag2 layout's pieces: schema text as rosbag2 writes it, QoS profiles as bag metadata
version 9 writes them, and the selection's rules."""

from __future__ import annotations

import pytest
import yaml

from cyborg.bus import MessageTypes, Qos
from cyborg.record.layout import channel_metadata, qos_profile, schema_text
from cyborg.record.selection import TopicSelection

TYPES = MessageTypes()


def test_schema_text_puts_each_dependency_once_after_80_equals_and_msg_line() -> None:
    text = schema_text(TYPES, "nav_msgs/msg/Path").decode()
    parts = text.split("\n" + "=" * 80 + "\n")
    assert parts[0].splitlines() == ["std_msgs/Header header",
                                     "geometry_msgs/PoseStamped[] poses"]
    names = [part.splitlines()[0] for part in parts[1:]]
    assert names == sorted(set(names), key=names.index)  # once each
    assert set(names) == {"MSG: std_msgs/Header", "MSG: builtin_interfaces/Time",
                          "MSG: geometry_msgs/PoseStamped", "MSG: geometry_msgs/Pose",
                          "MSG: geometry_msgs/Point", "MSG: geometry_msgs/Quaternion"}


def test_schema_text_of_an_unknown_type_names_it() -> None:
    with pytest.raises(KeyError, match="their_msgs/msg/Odd"):
        schema_text(TYPES, "their_msgs/msg/Odd")


def test_qos_profiles_are_a_yaml_sequence_with_string_policies() -> None:
    latched = Qos.latched(depth=5).to_keyexpr()
    metadata = channel_metadata(TYPES, "std_msgs/msg/String", [latched, Qos().to_keyexpr()])
    profiles = yaml.safe_load(metadata["offered_qos_profiles"])
    assert [(p["durability"], p["depth"], p["history"], p["reliability"]) for p in profiles] == [
        ("transient_local", 5, "keep_last", "reliable"), ("volatile", 42, "keep_last",
                                                          "reliable")]
    assert profiles[0]["deadline"] == {"sec": 9223372036, "nsec": 854775807}
    assert metadata["topic_type_hash"].startswith("RIHS01_")
    assert yaml.safe_load(channel_metadata(TYPES, "std_msgs/msg/String", [])[
        "offered_qos_profiles"]) == []
    assert "best_effort" in qos_profile("2:2:2,:,:,:,,")


def test_an_empty_exclude_pattern_is_refused() -> None:
    with pytest.raises(ValueError, match="--exclude: an empty pattern"):
        TopicSelection.of(exclude=[" "])
