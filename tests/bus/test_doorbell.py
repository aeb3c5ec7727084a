"""The doorbell: slot references between sessions of one machine by Unix datagram."""

from __future__ import annotations

import logging
import socket
import threading
from collections import Counter
from collections.abc import Iterator

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cyborg.bus import doorbell as bell
from cyborg.bus.doorbell import Doorbell, decode, doorbell_address, encode

pytestmark = pytest.mark.skipif(not bell.supported(), reason="abstract Unix sockets: Linux only")


class Drops:
    def __init__(self) -> None:
        self.counts: Counter[str] = Counter()

    def __call__(self, reason: str, detail: str = "") -> None:
        self.counts[reason] += 1


@pytest.fixture
def pair() -> Iterator[tuple[Doorbell, Doorbell, Drops]]:
    drops = Drops()
    ringer, answerer = Doorbell(7, "aa01", drops), Doorbell(7, "bb02", drops)
    yield ringer, answerer, drops
    ringer.close()
    answerer.close()


def receiver(doorbell: Doorbell, entity_id: int) -> tuple[list[tuple[bytes, bytes]],
                                                            threading.Event]:
    got: list[tuple[bytes, bytes]] = []
    arrived = threading.Event()

    def handle(attachment: bytes, reference: bytes) -> None:
        got.append((attachment, reference))
        arrived.set()
    doorbell.register(entity_id, handle)
    return got, arrived


@given(st.integers(0, 2**32 - 1), st.binary(max_size=64), st.binary(max_size=300))
def test_datagrams_decode_to_what_was_encoded(entity_id: int, attachment: bytes,
                                              reference: bytes) -> None:
    assert decode(encode(entity_id, attachment, reference)) == (entity_id, attachment, reference)


@given(st.binary(max_size=80))
def test_any_bytes_decode_or_raise_value_error(datagram: bytes) -> None:
    try:
        entity_id, attachment, reference = decode(datagram)
    except ValueError:
        return
    assert encode(entity_id, attachment, reference) == datagram


def test_a_ring_reaches_the_registered_subscription(pair: tuple[Doorbell, Doorbell, Drops]
                                                    ) -> None:
    ringer, answerer, drops = pair
    got, arrived = receiver(answerer, 5)
    assert ringer.ring([("bb02", 5)], b"A" * 33, b"slot reference")
    assert arrived.wait(2)
    assert got == [(b"A" * 33, b"slot reference")]
    assert answerer.answered == 1 and not drops.counts


def test_a_ring_without_a_doorbell_fails_so_the_publisher_uses_zenoh(
        pair: tuple[Doorbell, Doorbell, Drops]) -> None:
    ringer, answerer, _drops = pair
    got, arrived = receiver(answerer, 5)
    assert not ringer.ring([("cc03", 5), ("bb02", 5)], b"", b"ref")
    assert arrived.wait(2) and got == [(b"", b"ref")]  # the reachable one is still rung
    assert not ringer.ring([("bb02", 5)], b"", b"x" * (1 << 20))  # refused, never truncated


def test_unknown_entities_are_ignored_and_garbage_is_counted(
        pair: tuple[Doorbell, Doorbell, Drops]) -> None:
    ringer, answerer, drops = pair
    got, arrived = receiver(answerer, 5)
    assert ringer.ring([("bb02", 6)], b"", b"for a subscription that is gone")
    with socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM) as stranger:
        stranger.sendto(b"\x05\x00", answerer.address)  # truncated head
        stranger.sendto(encode(5, b"", b"")[:4] + b"\xff\x00", answerer.address)  # length lies
    assert ringer.ring([("bb02", 5)], b"", b"good")
    assert arrived.wait(2)
    assert got == [(b"", b"good")]
    assert drops.counts == Counter({"doorbell: malformed datagram": 2})


def test_a_handler_that_raises_is_logged_and_the_doorbell_keeps_answering(
        pair: tuple[Doorbell, Doorbell, Drops], caplog: pytest.LogCaptureFixture) -> None:
    ringer, answerer, _drops = pair
    answerer.register(1, lambda _a, _r: 1 / 0)
    got, arrived = receiver(answerer, 2)
    with caplog.at_level(logging.ERROR, logger="cyborg.bus"):
        assert ringer.ring([("bb02", 1), ("bb02", 2)], b"", b"ref")
        assert arrived.wait(2)
    assert got == [(b"", b"ref")]
    assert "doorbell handler of entity 1 raised" in caplog.text


def test_close_stops_the_thread_and_frees_the_address() -> None:
    drops = Drops()
    doorbell = Doorbell(3, "dd04", drops)
    doorbell.close()
    doorbell.close()  # twice is harmless
    assert not doorbell._thread.is_alive()
    with socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM) as probe, pytest.raises(OSError):
        probe.sendto(b"x", doorbell_address(3, "dd04"))
    again = Doorbell(3, "dd04", drops)  # the name can be bound again
    again.close()


def test_unregistered_subscriptions_get_nothing(pair: tuple[Doorbell, Doorbell, Drops]) -> None:
    ringer, answerer, _drops = pair
    got, _arrived = receiver(answerer, 9)
    answerer.unregister(9)
    second, arrived = receiver(answerer, 10)
    assert ringer.ring([("bb02", 9), ("bb02", 10)], b"", b"ref")
    assert arrived.wait(2)
    assert got == [] and second == [(b"", b"ref")]


@pytest.mark.filterwarnings("error::pytest.PytestUnhandledThreadExceptionWarning")
def test_close_returns_even_when_a_handler_hangs_with_a_full_queue() -> None:
    drops = Drops()
    ringer, stuck = Doorbell(5, "ee05", drops), Doorbell(5, "ff06", drops)
    release, entered = threading.Event(), threading.Event()

    def hang(_attachment: bytes, _reference: bytes) -> None:
        entered.set()
        release.wait(10)
    stuck.register(1, hang)
    assert ringer.ring([("ff06", 1)], b"", b"first")
    assert entered.wait(2)
    while ringer.ring([("ff06", 1)], b"", b"more"):  # until its queue is full
        pass
    closing = threading.Thread(target=stuck.close)
    closing.start()
    closing.join(5)
    assert not closing.is_alive(), "close() waited for the hanging handler's full queue"
    release.set()
    stuck._thread.join(2)  # the handler returns, the closed socket ends the thread quietly
    assert not stuck._thread.is_alive()
    ringer.close()
