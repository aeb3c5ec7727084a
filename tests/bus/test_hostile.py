"""Hostile input on the bus: forged sequence numbers and GIDs, poisoned shared-memory slots.

The victim is a session in this process; the attacker is a second session linked to it on
loopback, or any local process ringing its doorbell (see ``tests/bus_peer.py``). Every wait is
bounded, and a thread that an attack parks is released when the test ends.
"""

from __future__ import annotations

import logging
import os
import socket
import struct
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from cyborg.bus import Context, Node, doorbell
from cyborg.bus.shm import PREFIX, SHM_DIR, SlotRef
from cyborg.bus.topics import MAX_PUBLISHERS
from tests.bus.bus_peer import forged, linked_contexts, raw_put, ring, until_subscribed, wait_for

STRING = "std_msgs/msg/String"
needs_doorbell = pytest.mark.skipif(not doorbell.supported(), reason="Linux doorbell only")


@pytest.fixture
def pair() -> Iterator[tuple[Context, Context]]:
    with linked_contexts() as contexts:
        yield contexts


def listen(victim: Context, topic: str = "/chatter") -> tuple[Any, list[str]]:
    got: list[str] = []
    subscription = Node("listener", context=victim).create_subscription(
        topic, STRING, lambda message: got.append(message.data))
    return subscription, got


def string(context: Context, text: str) -> bytes:
    message = context.types.message_class(STRING)(data=text)
    return bytes(context.types.serialize(message, STRING))


# ---------------------------------------------------------------------- sequence numbers
def test_an_undecodable_sample_with_a_huge_sequence_does_not_mute_its_publisher(
        pair: tuple[Context, Context]) -> None:
    victim, attacker = pair
    _subscription, got = listen(victim)
    talker = Node("talker", context=attacker).create_publisher("/chatter", STRING)
    until_subscribed(attacker, "/chatter")
    talker.publish(talker._class(data="before"))
    assert wait_for(lambda: got == ["before"])
    raw_put(attacker, "/chatter", STRING, b"\x00\x01\x00\x00garbage", forged(2**63 - 1, talker.gid))
    assert wait_for(lambda: victim.dropped)
    talker.publish(talker._class(data="after"))
    assert wait_for(lambda: got == ["before", "after"], 2), "the publisher was muted"


def test_a_decodable_forged_sequence_is_taken_for_a_restart(
        pair: tuple[Context, Context]) -> None:
    victim, attacker = pair
    _subscription, got = listen(victim)
    talker = Node("talker", context=attacker).create_publisher("/chatter", STRING)
    until_subscribed(attacker, "/chatter")
    raw_put(attacker, "/chatter", STRING, string(attacker, "forged"),
            forged(2**63 - 1, talker.gid))
    assert wait_for(lambda: got == ["forged"])  # indistinguishable: the GID is public
    talker.publish(talker._class(data="real"))
    assert wait_for(lambda: got == ["forged", "real"], 2), "the publisher was muted"


def test_duplicates_are_still_dropped(pair: tuple[Context, Context]) -> None:
    victim, attacker = pair
    _subscription, got = listen(victim)
    until_subscribed(attacker, "/chatter")
    gid = os.urandom(16)
    for sequence, text in ((5, "a"), (5, "a again"), (4, "older"), (6, "b")):
        raw_put(attacker, "/chatter", STRING, string(attacker, text), forged(sequence, gid))
    assert wait_for(lambda: got == ["a", "b"])
    time.sleep(0.05)
    assert got == ["a", "b"]


def test_the_table_of_publishers_is_bounded(pair: tuple[Context, Context]) -> None:
    victim, attacker = pair
    subscription, got = listen(victim)
    until_subscribed(attacker, "/chatter")
    payload = string(attacker, "x")
    for _ in range(MAX_PUBLISHERS + 500):
        raw_put(attacker, "/chatter", STRING, payload, forged(1))  # a new GID every time
    raw_put(attacker, "/chatter", STRING, string(attacker, "last"), forged(1))
    assert wait_for(lambda: "last" in got, 10)
    assert len(subscription._last_sequence) == MAX_PUBLISHERS  # full, not beyond


def test_publishers_that_leave_the_graph_are_forgotten(pair: tuple[Context, Context]) -> None:
    victim, attacker = pair
    subscription, got = listen(victim)
    node = Node("talker", context=attacker)
    talker = node.create_publisher("/chatter", STRING)
    until_subscribed(attacker, "/chatter")
    talker.publish(talker._class(data="hello"))
    assert wait_for(lambda: got == ["hello"])
    assert talker.gid in subscription._last_sequence
    node.destroy()
    assert wait_for(lambda: talker.gid not in subscription._last_sequence, 5)


# ---------------------------------------------------------------------- shared-memory slots
def slot_file(path: Path, payload: bytes, generation: int = 7) -> SlotRef:
    """A slot as a publisher writes it: header (generation, length), then the payload."""
    path.write_bytes(struct.pack("<QQ", generation, len(payload)) + payload)
    path.chmod(0o600)
    return SlotRef(str(path), generation, len(payload))


@pytest.fixture
def shm_files() -> Iterator[list[Path]]:
    """Files the test makes in the shared-memory folder; FIFOs are opened for writing at the
    end, which releases any thread an attack left waiting to open them for reading."""
    made: list[Path] = []
    yield made
    for path in made:
        if path.is_fifo():
            for _ in range(20):
                try:
                    os.close(os.open(path, os.O_WRONLY | os.O_NONBLOCK))
                except OSError:  # no reader waits any more
                    break
                time.sleep(0.02)
        path.unlink(missing_ok=True)


def shm_path(made: list[Path], name: str) -> Path:
    path = SHM_DIR / f"{PREFIX}hostile-{os.getpid()}-{name}"
    path.unlink(missing_ok=True)
    made.append(path)
    return path


def send_reference(route: str, victim: Context, attacker: Context, subscription: Any,
                   ref: SlotRef) -> None:
    attachment = forged(1)
    if route == "doorbell":
        ring(victim, subscription.entity_id, attachment, ref.encode())
    else:
        attacker.session.put(victim.shm_key(subscription.key), ref.encode(),
                             attachment=attachment)


@needs_doorbell
@pytest.mark.parametrize("route", ["doorbell", "zenoh"])
def test_a_slot_reference_to_a_fifo_does_not_park_the_receiver(
        route: str, pair: tuple[Context, Context], shm_files: list[Path],
        caplog: pytest.LogCaptureFixture) -> None:
    victim, attacker = pair
    subscription, got = listen(victim)
    until_subscribed(attacker, "/chatter")
    fifo = shm_path(shm_files, "fifo")
    os.mkfifo(fifo, 0o600)
    good = slot_file(shm_path(shm_files, "good"), string(victim, "still here"))
    with caplog.at_level(logging.WARNING, "cyborg.bus"):
        for _ in range(20):
            send_reference(route, victim, attacker, subscription, SlotRef(str(fifo), 1, 10))
        send_reference(route, victim, attacker, subscription, good)
        assert wait_for(lambda: got == ["still here"], 3), "the receiving thread is parked"
    reason = next(r for r in victim.dropped if "refused shared-memory slot" in r)
    assert reason.startswith("/chatter") and victim.dropped[reason] == 20
    warnings = [r.getMessage() for r in caplog.records if "refused shared-memory" in r.getMessage()]
    assert len(warnings) == 1 and "/chatter" in warnings[0] and "FIFO" in warnings[0]


@needs_doorbell
def test_links_foreign_and_oversized_slot_files_are_refused(
        pair: tuple[Context, Context], shm_files: list[Path]) -> None:
    victim, attacker = pair
    subscription, got = listen(victim)
    until_subscribed(attacker, "/chatter")
    payload = string(victim, "smuggled")
    target = slot_file(shm_path(shm_files, "target"), payload)
    link = shm_path(shm_files, "link")
    link.symlink_to(target.path)
    refused = [SlotRef(str(link), target.generation, target.length)]
    huge = slot_file(shm_path(shm_files, "huge"), payload)
    os.truncate(huge.path, (1 << 30) + (1 << 20))  # sparse: costs no memory
    refused.append(huge)
    if os.geteuid() == 0:
        foreign = slot_file(shm_path(shm_files, "foreign"), payload)
        os.chown(foreign.path, 65534, 65534)
        refused.append(foreign)
    for ref in refused:
        send_reference("doorbell", victim, attacker, subscription, ref)
    reason = "/chatter: refused shared-memory slot"
    assert wait_for(lambda: victim.dropped[reason] == len(refused), 3), victim.dropped
    good = slot_file(shm_path(shm_files, "good"), string(victim, "fine"))
    send_reference("doorbell", victim, attacker, subscription, good)
    assert wait_for(lambda: got == ["fine"], 3)


@needs_doorbell
@pytest.mark.skipif(os.geteuid() != 0, reason="needs root to send as another user")
def test_the_doorbell_refuses_datagrams_from_other_users(
        pair: tuple[Context, Context], shm_files: list[Path]) -> None:
    victim, _attacker = pair
    subscription, got = listen(victim)
    ref = slot_file(shm_path(shm_files, "slot"), string(victim, "from nobody"))
    datagram = doorbell.encode(subscription.entity_id, forged(1), ref.encode())
    address = doorbell.doorbell_address(victim.domain, victim.zid)
    with socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM) as sender:
        child = os.fork()
        if child == 0:  # as "nobody", send one datagram and leave at once
            try:
                os.setgid(65534)
                os.setuid(65534)
                sender.sendto(datagram, address)
            finally:
                os._exit(0)
        os.waitpid(child, 0)
    assert wait_for(lambda: victim.dropped["doorbell: datagram from another user"] == 1, 3)
    assert got == []
