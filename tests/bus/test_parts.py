"""Pieces of the bus on their own: connection settings, graph tokens, shared-memory slots."""

from __future__ import annotations

import gc
import json
import os
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.bus import BusConfig, BusConfigError
from cyborg.bus.graph import Graph, parse_token
from cyborg.bus.shm import PREFIX, SHM_DIR, SlotReader, SlotRef, SlotWriter, remove_stale_slots
from cyborg.bus.wire import EntityKind

DESIGN_EXAMPLE = ("@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/10/MS/%/%/listener/%chatter/"
                  "std_msgs::msg::dds_::String_/RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db12880"
                  "21743503259e948f6b1a18/::,10:,:,:,,")


# ---------------------------------------------------------------------- connection settings
def test_default_is_a_loopback_peer_without_multicast() -> None:
    config = BusConfig.from_environment(environ={})
    assert (config.mode, config.connect, config.listen) == (
        "peer", ("tcp/127.0.0.1:7447",), ("tcp/127.0.0.1:0",))
    zenoh_config = json.loads(str(config.to_zenoh()))
    assert zenoh_config["scouting"]["multicast"]["enabled"] is False
    assert zenoh_config["listen"]["endpoints"] == ["tcp/127.0.0.1:0"]


def test_connect_from_flag_then_environment(tmp_path: Path) -> None:
    env = {"CYBORG_CONNECT": "tcp/10.0.0.2:7447, tcp/10.0.0.3:7447",
           "ZENOH_CONFIG_OVERRIDE": "transport/shared_memory/enabled=false"}
    assert BusConfig.from_environment(environ=env).connect == (
        "tcp/10.0.0.2:7447", "tcp/10.0.0.3:7447")
    assert BusConfig.from_environment(["tcp/robot:7447"], environ=env).connect == (
        "tcp/robot:7447",)
    zenoh_config = json.loads(str(BusConfig.from_environment(environ=env).to_zenoh()))
    assert zenoh_config["transport"]["shared_memory"]["enabled"] is False


@pytest.mark.parametrize(("config", "error"), [
    (BusConfig(connect=("192.168.1.10:7447",)), "endpoint '192.168.1.10:7447': expected"),
    (BusConfig(mode="server"), "mode 'server'"),
    (BusConfig(overrides=(("transport/nope", "{{"),)), "ZENOH_CONFIG_OVERRIDE: transport/nope"),
    (BusConfig(config_file=Path("/nonexistent/zenoh.json5")),
     "ZENOH_SESSION_CONFIG_URI=/nonexistent/zenoh.json5"),
])
def test_bad_settings_are_named(config: BusConfig, error: str) -> None:
    with pytest.raises(BusConfigError, match=error):
        config.to_zenoh()


def test_override_without_equals_is_refused() -> None:
    with pytest.raises(BusConfigError, match="'mode' is not KEY=VALUE"):
        BusConfig.from_environment(environ={"ZENOH_CONFIG_OVERRIDE": "mode"})


# ---------------------------------------------------------------------- graph tokens
def test_parse_the_design_document_token() -> None:
    entity = parse_token(DESIGN_EXAMPLE)
    assert entity is not None
    assert (entity.domain, entity.kind, entity.node_name, entity.topic, entity.type_name) == (
        2, EntityKind.SUBSCRIPTION, "/listener", "/chatter", "std_msgs/msg/String")
    assert entity.zid == "aac3178e146ba6f1fc6e6a4085e77f21" and not entity.latched


@pytest.mark.parametrize("key", [
    "@ros2_lv/0/zid/x/1/NN/%/%/node",  # node id not a number
    "@ros2_lv/0/zid/1/1/XX/%/%/node",  # unknown kind
    "@ros2_lv/0/zid/1/1/NN/%/%/node/extra",  # wrong length
    "@other/0/zid/1/1/NN/%/%/node",
])
def test_foreign_tokens_are_ignored(key: str) -> None:
    assert parse_token(key) is None


def test_graph_tracks_tokens_of_its_domain() -> None:
    graph = Graph(domain=2)
    graph.add(DESIGN_EXAMPLE)
    graph.add("@ros2_lv/2/aac3/0/0/NN/%/%robot1/listener")
    graph.add("@ros2_lv/3/aac3/0/0/NN/%/%/elsewhere")
    assert graph.nodes() == ["/robot1/listener"]
    assert graph.topics() == {"/chatter": {"std_msgs/msg/String"}}
    assert graph.count("/chatter", EntityKind.SUBSCRIPTION) == 1
    assert graph.count("/chatter", EntityKind.SUBSCRIPTION, exclude_zid="aac3178e146ba6f1fc"
                       "6e6a4085e77f21") == 0
    graph.remove(DESIGN_EXAMPLE)
    assert graph.topics() == {}
    assert graph.count("/chatter", EntityKind.SUBSCRIPTION) == 0


def _endpoint_token(zid: str, kind: str, topic: str, entity_id: int) -> str:
    return (f"@ros2_lv/0/{zid}/1/{entity_id}/{kind}/%/%/node/%{topic}/"
            "std_msgs::msg::dds_::String_/RIHS01_00/::,10:,:,:,,")


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.booleans(), st.sampled_from(["a", "b"]),
                          st.sampled_from(["MP", "MS", "SS"]), st.sampled_from(["x", "y"]),
                          st.integers(1, 3)), max_size=40))
def test_endpoint_counts_follow_every_add_and_remove(
        steps: list[tuple[bool, str, str, str, int]]) -> None:
    """The per-topic index a publisher asks on every message agrees with the token set."""
    graph, alive = Graph(domain=0), set()
    for adding, zid, kind, topic, entity_id in steps:
        key = _endpoint_token(zid, kind, topic, entity_id)
        if adding:
            graph.add(key)
            alive.add(key)
        else:
            graph.remove(key)
            alive.discard(key)
    entities = [entity for entity in map(parse_token, alive) if entity is not None]
    for topic in ("/x", "/y"):
        for kind in (EntityKind.PUBLISHER, EntityKind.SUBSCRIPTION, EntityKind.SERVICE_SERVER):
            expected = [e for e in entities if e.topic == topic and e.kind is kind]
            assert sorted(e.key for e in graph.endpoints(topic, kind)) == sorted(
                e.key for e in expected)
            assert graph.count(topic, kind, exclude_zid="a") == sum(
                e.zid != "a" for e in expected)


# ---------------------------------------------------------------------- shared-memory slots
def fill_with(value: int) -> Callable[[memoryview], object]:
    return lambda view: view.__setitem__(slice(None), bytes([value]) * len(view))


def test_a_leased_slot_is_never_overwritten() -> None:
    writer, reader = SlotWriter(max_slots=2, reuse_grace=0.0), SlotReader()
    try:
        first = writer.write(8, fill_with(1))
        assert first is not None
        lease = reader.read(SlotRef.decode(first.encode()))
        assert lease is not None and lease.tolist() == [1] * 8
        assert not lease.flags.writeable
        view = lease[2:4]
        del lease
        for value in (2, 3, 4):  # the other slot takes every write while the view lives
            written = writer.write(8, fill_with(value))
            assert written is not None and written.path != first.path
        assert view.tolist() == [1, 1]
        del view
        gc.collect()
        reused = writer.write(8, fill_with(5))
        assert reused is not None
        assert reader.read(first) is None or reused.path != first.path
    finally:
        writer.close()


def test_all_slots_leased_means_no_slot() -> None:
    writer, reader = SlotWriter(max_slots=2), SlotReader()
    try:
        leases = []
        for value in range(2):
            ref = writer.write(4, fill_with(value))
            assert ref is not None
            leases.append(reader.read(ref))
        assert [lease.tolist() for lease in leases if lease is not None] == [[0] * 4, [1] * 4]
        assert writer.write(4, fill_with(9)) is None
    finally:
        writer.close()


def test_a_reused_slot_is_reported_not_read() -> None:
    writer, reader = SlotWriter(max_slots=1, reuse_grace=0.0), SlotReader()
    try:
        old = writer.write(4, fill_with(1))
        assert writer.write(4, fill_with(2)) is not None  # nobody leased the first
        assert old is not None and reader.read(old) is None
        assert reader.read(SlotRef(old.path + "-gone", 1, 4)) is None
    finally:
        writer.close()
    assert not Path(old.path).exists()


def test_a_burst_gets_fresh_slots_until_its_readers_had_time_to_lock() -> None:
    """Two frames published back to back: the first one's reader has not locked its slot
    yet, so the second must not overwrite it (it did, before the grace)."""
    writer, reader = SlotWriter(max_slots=2, reuse_grace=0.05), SlotReader()
    try:
        first = writer.write(4, fill_with(1))
        second = writer.write(4, fill_with(2))
        assert first is not None and second is not None and second.path != first.path
        assert writer.write(4, fill_with(3)) is None, "both are fresh: send inline instead"
        lease = reader.read(first)
        assert lease is not None and lease.tolist() == [1] * 4
        del lease
        gc.collect()
        time.sleep(0.06)
        reused = writer.write(4, fill_with(4))
        assert reused is not None and reused.path == second.path, "the last one, warm, again"
    finally:
        writer.close()


def test_a_bigger_message_gets_a_bigger_slot() -> None:
    writer, reader = SlotWriter(max_slots=1, reuse_grace=0.0), SlotReader()
    try:
        assert writer.write(10, fill_with(1)) is not None
        big = writer.write(3 << 20, fill_with(7))
        assert big is not None
        lease = reader.read(big)
        assert lease is not None and len(lease) == 3 << 20 and int(lease[-1]) == 7
    finally:
        writer.close()


def test_bad_slot_references_are_refused() -> None:
    with pytest.raises(ValueError, match="too short"):
        SlotRef.decode(b"xx")
    with pytest.raises(ValueError, match="not a cyborg"):
        SlotRef.decode(SlotRef("/etc/passwd", 1, 4).encode())
    for elsewhere in (f"/tmp/{PREFIX}1-x", f"{SHM_DIR}/deeper/{PREFIX}1-x",
                      f"{SHM_DIR}/{PREFIX}1-x/../../etc/passwd"):
        with pytest.raises(ValueError, match="not a cyborg"):  # only slot files in SHM_DIR
            SlotRef.decode(SlotRef(elsewhere, 1, 4).encode())
    good = SlotRef(f"{SHM_DIR}/{PREFIX}1-x", 1, 4)
    assert SlotRef.decode(good.encode()) == good
    with pytest.raises(ValueError, match="not a cyborg"):  # the length disagrees
        SlotRef.decode(good.encode()[:-1])


def test_slots_of_dead_processes_are_removed(tmp_path: Path) -> None:
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True).stdout.strip()
    stale = tmp_path / f"{PREFIX}{dead}-abcd-1"
    mine = tmp_path / f"{PREFIX}{os.getpid()}-abcd-1"
    for path in (stale, mine):
        path.write_bytes(np.zeros(4, np.uint8).tobytes())
    assert remove_stale_slots(tmp_path) == 1
    assert not stale.exists() and mine.exists()
