"""Pairing the streams of a camera by exact stamp (cyborg.vision.pairing.ExactPairer).

A set is returned when its last item comes; what a newer set overtook, what is left at the end
and what overflows the bound is dropped and counted; hypothesis checks that every item is
accounted for and that complete streams lose nothing.
"""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.vision.pairing import ExactPairer


def test_pairer_returns_the_complete_set() -> None:
    pairer = ExactPairer(("image", "depth"))
    assert pairer.add("image", 10, "i10") is None
    assert pairer.add("depth", 10, "d10") == {"image": "i10", "depth": "d10"}
    assert pairer.add("depth", 20, "d20") is None
    assert pairer.add("image", 20, "i20") == {"image": "i20", "depth": "d20"}
    assert pairer.dropped == 0 and not pairer.pending


def test_pairer_drops_what_a_newer_pair_overtook_and_what_is_left_at_the_end() -> None:
    pairer = ExactPairer(("image", "depth"))
    pairer.add("image", 1, "i1")
    pairer.add("depth", 2, "d2")
    pairer.add("image", 5, "i5")
    assert pairer.add("depth", 3, "d3") is None
    assert pairer.add("depth", 4, "d4") is None
    assert pairer.add("image", 3, "i3") == {"image": "i3", "depth": "d3"}
    assert pairer.dropped == 2  # i1, d2
    assert list(pairer.pending) == [5, 4]
    pairer.finish()
    assert pairer.dropped == 4 and not pairer.pending


def test_pairer_keeps_the_newer_of_two_items_of_one_stamp() -> None:
    pairer = ExactPairer(("image", "depth"))
    pairer.add("image", 1, "first")
    pairer.add("image", 1, "second")
    assert pairer.add("depth", 1, "d") == {"image": "second", "depth": "d"}
    assert pairer.dropped == 1


def test_pairer_bounds_what_waits() -> None:
    pairer = ExactPairer(("image", "depth", "right"), max_pending=3)
    for stamp in range(5):
        pairer.add("image", stamp, stamp)
    pairer.add("depth", 4, "d4")
    assert list(pairer.pending) == [2, 3, 4] and pairer.dropped == 2
    pairer.add("right", 2, "r2")
    assert pairer.add("depth", 2, "d2") == {"image": 2, "right": "r2", "depth": "d2"}
    assert list(pairer.pending) == [3, 4]
    pairer.finish()
    assert pairer.dropped == 2 + 3  # image 3, image 4 and depth 4


def test_pairer_of_one_stream_and_bad_streams() -> None:
    pairer = ExactPairer(("image",))
    assert pairer.add("image", 1, "a") == {"image": "a"}
    with pytest.raises(KeyError, match="unknown stream 'depth'"):
        pairer.add("depth", 1, "b")
    for streams in ((), ("image", "image")):
        with pytest.raises(ValueError, match="distinct"):
            ExactPairer(streams)


@settings(max_examples=60, deadline=None)
@given(items=st.lists(st.tuples(st.sampled_from(["image", "depth", "right"]),
                                st.integers(0, 8)), max_size=40),
       max_pending=st.integers(1, 5), stereo=st.booleans())
def test_pairer_accounts_for_every_item(items: list[tuple[str, int]], max_pending: int,
                                        stereo: bool) -> None:
    streams = ("image", "depth", "right") if stereo else ("image", "depth")
    items = [(stream, stamp) for stream, stamp in items if stream in streams]
    pairer = ExactPairer(streams, max_pending=max_pending)
    returned = 0
    for serial, (stream, stamp) in enumerate(items):
        complete = pairer.add(stream, stamp, (stream, stamp, serial))
        assert len(pairer.pending) <= max_pending
        if complete is not None:
            assert sorted(complete) == sorted(streams)
            assert all(item[:2] == (name, stamp) for name, item in complete.items())
            assert complete[stream][2] == serial  # the item just added completed it
            returned += len(complete)
        waiting = sum(len(group) for group in pairer.pending.values())
        assert returned + pairer.dropped + waiting == serial + 1
    pairer.finish()
    assert returned + pairer.dropped == len(items)


@settings(max_examples=20, deadline=None)
@given(stamps=st.lists(st.integers(0, 10**18), unique=True, max_size=20).map(sorted),
       depth_first=st.lists(st.booleans(), min_size=20, max_size=20))
def test_pairer_loses_nothing_of_complete_streams(stamps: list[int],
                                                 depth_first: list[bool]) -> None:
    pairer = ExactPairer(("image", "depth"), max_pending=2)
    paired = []
    for stamp, depth_leads in zip(stamps, depth_first, strict=False):
        order = ("depth", "image") if depth_leads else ("image", "depth")
        assert pairer.add(order[0], stamp, stamp) is None
        complete = pairer.add(order[1], stamp, stamp)
        assert complete == {"image": stamp, "depth": stamp}
        paired.append(stamp)
    pairer.finish()
    assert paired == stamps and pairer.dropped == 0
