"""The simulated camera: what is in view is detected, what is behind a wall, a body or the
camera is not; distances with noise that grows with range; misses; boxes from the pinhole."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cyborg.interfaces.simulation import PERSON_LABEL
from cyborg.nav.arnl_map import MapError, parse_map
from cyborg.nav.grid import MapGrid
from cyborg.sim.camera import CameraSpec, SeenObject, SimCamera
from cyborg.sim.sights import OBJECT_HEIGHT, OBJECT_RADIUS, Sights, placed_objects
from tests.small_maps import room_map

# a 10 x 6 m room split at x = 5 m by a wall with a door at y 2.4..3.6 m
WORLD = MapGrid.from_map(parse_map(room_map([]), "room.map"), 0.05)
OPEN = MapGrid.from_map(parse_map(room_map([], lines=[]).replace(
    "5000 0 5000 2400\n5000 3600 5000 6000\n", ""), "open.map"), 0.05)


def camera(world: MapGrid = WORLD, seed: int = 0, **spec: float) -> SimCamera:
    return SimCamera(world.walls, (world.origin_x, world.origin_y), world.resolution,
                     CameraSpec(**spec), seed=seed)  # type: ignore[arg-type]


def people(*where: tuple[float, float]) -> Sights:
    count = len(where)
    return Sights((PERSON_LABEL,) * count, np.array(where, dtype=float).reshape(-1, 2),
                  np.full(count, 0.25), np.full(count, 1.7))


def frames(cam: SimCamera, pose: tuple[float, float, float], sights: Sights,
           count: int = 200, **kwargs: object) -> list[list[SeenObject]]:
    return [cam.observe(*pose, sights, **kwargs) for _ in range(count)]  # type: ignore[arg-type]


def test_a_person_in_view_is_detected_as_the_detector_would_report_it() -> None:
    seen = frames(camera(), (1.0, 1.5, 0.0), people((4.0, 1.5)))
    found = [frame[0] for frame in seen if frame]
    assert len(found) > 0.9 * len(seen)
    item = found[0]
    assert item.label == "person" and 0.5 <= item.confidence <= 0.99
    x1, y1, x2, y2 = item.box
    spec = CameraSpec()
    assert 0 <= x1 < x2 <= spec.width and 0 <= y1 < y2 <= spec.height
    assert (x1 + x2) / 2 == pytest.approx(spec.width / 2, abs=15), "straight ahead: the middle"
    assert y2 == pytest.approx(spec.height / 2 + spec.focal * spec.mount_height / 2.85, rel=0.2)
    assert np.median([f.distance for f in found]) == pytest.approx(3.0 - spec.mount_x, abs=0.05)


def test_a_person_to_the_left_is_on_the_left_of_the_image() -> None:
    found = [f[0] for f in frames(camera(OPEN), (1.0, 1.5, 0.0), people((4.0, 3.5))) if f]
    bearing = math.atan2(2.0, 3.0 - CameraSpec().mount_x)
    middle = np.median([(f.box[0] + f.box[2]) / 2 for f in found])
    spec = CameraSpec()
    assert middle == pytest.approx(spec.width / 2 - spec.focal * math.tan(bearing), abs=10)


def test_nobody_behind_a_wall_outside_the_view_or_out_of_range_is_detected() -> None:
    cam = camera()
    behind_wall = people((7.0, 1.5))  # the wall at x = 5 m stands between
    assert not any(frames(cam, (3.0, 1.5, 0.0), behind_wall))
    behind_camera = people((1.0, 1.5))
    assert not any(frames(cam, (3.0, 1.5, 0.0), behind_camera))
    beside = people((3.2, 4.5))  # 65 degrees to the left: outside the 110 degree view
    assert not any(frames(cam, (3.0, 1.5, 0.0), beside))
    far = people((9.0, 1.5))
    assert not any(frames(camera(OPEN, range_max=5.0), (1.0, 1.5, 0.0), far))
    assert any(frames(camera(OPEN), (1.0, 1.5, 0.0), far)), "in range, in the open: seen"


def test_a_person_hidden_behind_another_is_not_detected() -> None:
    two = people((3.0, 1.5), (5.0, 1.5))
    seen = frames(camera(OPEN), (1.0, 1.5, 0.0), two)
    distances = [f.distance for frame in seen for f in frame]
    assert distances and max(distances) < 3.0, "only the near one"
    behind_a_robot = people((5.0, 1.5))
    robot = np.array([[2.8, 1.2], [3.3, 1.2], [3.3, 1.8], [2.8, 1.8]])
    assert not any(frames(camera(OPEN), (1.0, 1.5, 0.0), behind_a_robot, bodies=(robot,)))
    stranger = np.array([[3.0, 1.5, 0.25]])
    assert not any(frames(camera(OPEN), (1.0, 1.5, 0.0), behind_a_robot, circles=stranger))


def test_distance_noise_is_small_near_and_grows_with_range() -> None:
    spec = CameraSpec()
    errors = {}
    for distance in (2.0, 15.0):
        sights = Sights(("person",), np.array([[distance + spec.mount_x, 0.0]]),
                        np.array([0.25]), np.array([1.7]))
        big = MapGrid.from_map(parse_map(room_map([], lines=[(0, -3000, 30000, -3000)])
                                         .replace("10000 0 10000 6000\n", ""), "long.map"), 0.1)
        cam = SimCamera(np.zeros_like(big.walls), (big.origin_x, big.origin_y), big.resolution,
                        spec, seed=3)
        found = [f[0].distance for f in frames(cam, (0.0, 0.0, 0.0), sights, 400) if f]
        errors[distance] = np.abs(np.array(found) - distance)
    assert np.median(errors[2.0]) < 0.03
    assert np.median(errors[15.0]) > 5 * np.median(errors[2.0])
    assert len(errors[15.0]) < 0.8 * 400, "far away, detections are missed"
    assert len(errors[2.0]) > 0.9 * 400


def test_a_reported_distance_stays_within_the_cameras_depth_range() -> None:
    spec = CameraSpec()
    sights = Sights(("person",), np.array([[spec.range_max - 0.05 + spec.mount_x, 0.0]]),
                    np.array([0.25]), np.array([1.7]))
    long = MapGrid.from_map(parse_map(room_map([], lines=[(0, -3000, 30000, -3000)])
                                      .replace("10000 0 10000 6000\n", ""), "long.map"), 0.1)
    cam = SimCamera(np.zeros_like(long.walls), (long.origin_x, long.origin_y), long.resolution,
                    spec, seed=5)
    found = [f[0].distance for f in frames(cam, (0.0, 0.0, 0.0), sights, 400) if f]
    assert found and max(found) <= spec.range_max, "noise never reports beyond the range"
    assert min(found) < spec.range_max - 0.2, "the noise is still there"


def test_the_same_seed_sees_the_same() -> None:
    sights = people((4.0, 1.5), (3.5, 2.0))
    first = frames(camera(seed=7), (1.0, 1.5, 0.0), sights, 20)
    assert first == frames(camera(seed=7), (1.0, 1.5, 0.0), sights, 20)
    assert first != frames(camera(seed=8), (1.0, 1.5, 0.0), sights, 20)


def test_objects_placed_on_the_map_are_sights_with_their_label_and_size() -> None:
    arnl_map = parse_map(room_map(['Sim.Object 3000 1500 0 "chair 0.9 0.3" ICON "c1"',
                                   'Sim.Object 4000 1500 0 "potted plant" ICON "p"']), "o.map")
    sights = placed_objects(arnl_map)
    assert sights.labels == ("chair", "potted plant")
    assert sights.positions.tolist() == [[3.0, 1.5], [4.0, 1.5]]
    assert sights.heights.tolist() == [0.9, OBJECT_HEIGHT]
    assert sights.radii.tolist() == [0.3, OBJECT_RADIUS]
    seen = frames(camera(), (1.0, 1.5, 0.0), sights, 50)
    assert {f.label for frame in seen for f in frame} == {"chair"}, "the plant is behind it"


@pytest.mark.parametrize(("description", "said"), [
    ("0.9 0.3", r"o\.map:3: Sim\.Object 'c1': the description '0\.9 0\.3' names no label"),
    ("chair -1", r"o\.map:3: Sim\.Object 'c1': height and radius must be positive"),
])
def test_a_bad_object_on_the_map_is_an_error_naming_the_line(description: str, said: str) -> None:
    arnl_map = parse_map(room_map([f'Sim.Object 3000 1500 0 "{description}" ICON "c1"']),
                         "o.map")
    with pytest.raises(MapError, match=said):
        placed_objects(arnl_map)
