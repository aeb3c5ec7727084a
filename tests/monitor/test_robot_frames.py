"""The robot's body and the laser's place on it as the map panel gets them
(cyborg.monitor.robot_wire): footprints in metres and refused when absurd, ``/tf_static``'s
transforms read in the plane and chained into the laser's mount; hostile values never raise."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.monitor.robot_wire import (
    BODY_LIMIT,
    FOOTPRINT_LIMIT,
    footprint_wire,
    mount_of,
    transforms_wire,
    wire_text,
)
from tests.monitor.robot_messages import footprint, transforms


def test_a_footprint_is_its_corners_in_metres_to_a_millimetre() -> None:
    payload, warnings = footprint_wire(footprint([(0.32, 0.18), (-0.32, 0.18004),
                                                  (-0.32, -0.18)]))
    assert payload == [0.32, 0.18, -0.32, 0.18, -0.32, -0.18] and warnings == []


@pytest.mark.parametrize(("corners", "said"), [
    ([(0.0, 0.0), (1.0, 0.0)], "2 corners, not 3 to 256"),
    ([(0.0, 0.0)] * (FOOTPRINT_LIMIT + 1), "257 corners"),
    ([(0.0, 0.0), (math.nan, 0.0), (1.0, 1.0)], "nan m is not a corner"),
    ([(0.0, 0.0), (1.0, 0.0), (1.0, BODY_LIMIT * 2)], "200 m is not a corner within 100 m"),
])
def test_an_absurd_footprint_is_refused_with_a_warning(corners: list[tuple[float, float]],
                                                      said: str) -> None:
    payload, warnings = footprint_wire(footprint(corners))
    assert payload is None and len(warnings) == 1
    assert warnings[0].startswith("footprint: ") and said in warnings[0]


def test_transforms_are_read_in_the_plane() -> None:
    found, warnings = transforms_wire(transforms(("base_link", "laser", 0.267, 0.0, 0.0),
                                                 ("base_link", "camera", 0.1, -0.05, math.pi / 2)))
    assert warnings == []
    assert found["laser"] == ("base_link", [0.267, 0.0, 0.0])
    parent, (x, y, theta) = found["camera"]
    assert (parent, x, y) == ("base_link", 0.1, -0.05)
    assert theta == pytest.approx(math.pi / 2)


def test_the_mount_is_the_scans_frame_chained_up_to_the_robot() -> None:
    found, _ = transforms_wire(transforms(("base_link", "mast", 0.1, 0.0, math.pi / 2),
                                          ("mast", "laser", 0.2, 0.0, math.pi / 2)))
    assert mount_of("laser", found) == [0.1, 0.2, round(math.pi, 3)]
    assert mount_of("mast", found) == [0.1, 0.0, round(math.pi / 2, 3)]
    assert mount_of("camera", found) is None


def test_a_loop_of_transforms_ends() -> None:
    found, _ = transforms_wire(transforms(("b", "a", 1.0, 0.0, 0.0), ("a", "b", 1.0, 0.0, 0.0)))
    assert mount_of("a", found) == [2.0, 0.0, 0.0]


def test_a_transform_that_is_not_finite_or_too_long_is_left_out() -> None:
    found, warnings = transforms_wire(transforms(("base_link", "laser", math.nan, 0.0, 0.0),
                                                 ("base_link", "far", 1e6, 0.0, 0.0),
                                                 ("base_link", "ok", 0.1, 0.0, 0.0)))
    assert sorted(found) == ["ok"]
    assert len(warnings) == 2 and all(w.startswith("tf: the transform 'base_link' -> ")
                                      for w in warnings)


ANY_FLOAT = st.floats(allow_nan=True, allow_infinity=True, width=64)


@settings(max_examples=200, deadline=None)
@given(corners=st.lists(st.tuples(st.floats(width=32), st.floats(width=32)), max_size=20))
def test_any_footprint_never_raises(corners: list[tuple[float, float]]) -> None:
    payload, warnings = footprint_wire(footprint(corners))
    assert (payload is None) == bool(warnings)
    wire_text({"fp": payload, "w": warnings})


@settings(max_examples=200, deadline=None)
@given(links=st.lists(st.tuples(st.sampled_from(["base_link", "a", "laser"]),
                                st.sampled_from(["a", "laser", "b"]),
                                ANY_FLOAT, ANY_FLOAT, ANY_FLOAT), max_size=6))
def test_any_transforms_never_raise(links: list[tuple[str, str, float, float, float]]) -> None:
    found, warnings = transforms_wire(transforms(*links))
    mount = mount_of("laser", found)
    wire_text({"m": mount, "w": warnings})
    assert mount is None or all(math.isfinite(value) for value in mount)


def test_robots_frames_named_after_them_give_each_robot_its_own_mount() -> None:
    """Several robots on one /tf_static (a fleet names its frames robot1/..., as ROS's tf
    prefix does): each scan's frame resolves to its own robot's mount."""
    found: dict[str, tuple[str, list[float]]] = {}
    for index, mount_x in enumerate((0.267, 0.3, 0.1), 1):
        transforms_found, warnings = transforms_wire(transforms(
            (f"robot{index}/base_link", f"robot{index}/laser", mount_x, 0.0, 0.0)))
        assert warnings == []
        found.update(transforms_found)
    assert [mount_of(f"robot{index}/laser", found) for index in (1, 2, 3)] == [
        [0.267, 0.0, 0.0], [0.3, 0.0, 0.0], [0.1, 0.0, 0.0]]
    assert mount_of("laser", found) is None, "the plain name is another robot's"
