"""The annotated image: outlines, labels, and the one-pass copy-and-draw kernel."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.vision.annotate import (
    BOX_COLOUR,
    LABEL_GREY,
    Overlay,
    annotate,
    caption,
    copy_frame,
    draw_detections,
)
from cyborg.vision.detector import Detection

WIDTH, HEIGHT = 1920, 1080


def photo(width: int = WIDTH, height: int = HEIGHT, seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).integers(0, 200, (height, width, 3), dtype=np.uint8)


def person(box: tuple[float, float, float, float], distance: float = 2.5) -> Detection:
    return Detection("person", 0, 0.93, box, distance=distance)


def reference(image: np.ndarray, overlay: Overlay) -> np.ndarray:
    """The same drawing with plain numpy slices: every box band, then every label patch."""
    drawn = image.copy()
    height, width = image.shape[:2]
    t = overlay.thickness

    def fill(x0: int, y0: int, x1: int, y1: int) -> None:
        x0, y0, x1, y1 = max(x0, 0), max(y0, 0), min(x1, width), min(y1, height)
        if x0 < x1 and y0 < y1:
            drawn[y0:y1, x0:x1] = BOX_COLOUR

    for left, top, right, bottom in overlay.boxes.tolist():
        fill(left, top, right, top + t)
        fill(left, bottom - t, right, bottom)
        fill(left, top, left + t, bottom)
        fill(right - t, top, right, bottom)
    for x0, y0, w, h, first in overlay.labels.tolist():
        for y in range(max(y0, 0), min(y0 + h, height)):
            for x in range(max(x0, 0), min(x0 + w, width)):
                drawn[y, x] = overlay.atlas[first + y - y0, x - x0]  # grey: all three channels
    return drawn


def test_the_frame_is_copied_and_left_as_it_was() -> None:
    image = photo()
    original = image.copy()
    annotated = annotate(image, [person((100.0, 200.0, 500.0, 900.0))])
    assert np.array_equal(image, original)
    assert annotated.shape == image.shape and not np.shares_memory(annotated, image)


def test_outlines_follow_the_box_edges_and_leave_the_inside_alone() -> None:
    image = photo()
    annotated = annotate(image, [person((100.0, 200.0, 500.0, 900.0))])
    green = np.array(BOX_COLOUR, dtype=np.uint8)
    for x, y in ((300, 900), (100, 600), (500, 600), (490, 200), (499, 899)):
        assert np.array_equal(annotated[y, x], green), (x, y)
    for x, y in ((300, 600), (50, 600), (600, 600), (300, 950), (103, 203)):
        assert np.array_equal(annotated[y, x], image[y, x]), (x, y)
    changed = np.any(annotated != image, axis=2)
    assert not changed[:150].any() and not changed[:, 510:].any() and not changed[910:].any()


def test_the_label_sits_above_the_box_with_its_caption() -> None:
    image = photo()
    detection = person((100.0, 200.0, 500.0, 900.0))
    overlay = Overlay.of(WIDTH, HEIGHT, [detection])
    x0, y0, w, h, _first = overlay.labels[0].tolist()
    assert (x0, y0 + h - 1) == (100, 200) and w > 200 and 20 < h < 60
    label = annotate(image, [detection])[y0:y0 + h, x0:x0 + w]
    white = np.all(label == LABEL_GREY, axis=2).mean()
    dark = np.all(label < 100, axis=2).mean()
    assert white > 0.6 and dark > 0.03  # a white patch with black text on it


def test_a_label_without_room_above_goes_inside_the_box() -> None:
    overlay = Overlay.of(WIDTH, HEIGHT, [person((10.0, 0.0, 300.0, 300.0))])
    assert overlay.labels[0, 1] == 0


def test_captions_say_unknown_distance_as_a_question_mark() -> None:
    assert caption(person((0, 0, 1, 1), distance=math.nan)) == "person: 0.93 (? m)"
    assert caption(person((0, 0, 1, 1), distance=2.371)) == "person: 0.93 (2.37 m)"


def test_in_place_drawing_matches_the_copy_and_refuses_read_only_images() -> None:
    image = photo(640, 480)
    detections = [person((20.0, 30.0, 200.0, 400.0)), person((150.0, 100.0, 630.0, 470.0))]
    drawn = image.copy()
    assert draw_detections(drawn, detections) is drawn
    assert np.array_equal(drawn, annotate(image, detections))
    strided = np.zeros((480, 1280, 3), dtype=np.uint8)[:, ::2]  # not contiguous
    strided[...] = image
    draw_detections(strided, detections)
    assert np.array_equal(strided, drawn)
    image.flags.writeable = False
    with pytest.raises(ValueError, match="read-only"):
        draw_detections(image, detections)


def test_images_that_are_not_bgr_are_refused_clearly() -> None:
    with pytest.raises(ValueError, match=r"BGR uint8 image .* \(480, 640\)"):
        annotate(np.zeros((480, 640), dtype=np.uint8), [])
    with pytest.raises(ValueError, match="float32"):
        annotate(np.zeros((480, 640, 3), dtype=np.float32), [])


def test_a_frame_is_only_copied_into_a_buffer_that_fits() -> None:
    image = photo(320, 240)
    assert copy_frame(image, np.empty_like(image)).tobytes() == image.tobytes()
    for wrong in (np.empty((240, 321, 3), np.uint8), np.empty((240, 320, 3), np.float32),
                  np.empty((240, 640, 3), np.uint8)[:, ::2]):
        with pytest.raises(ValueError, match=r"copy_frame: into must be a writable "
                                             r"C-contiguous uint8 array of shape \(240, 320, 3\)"):
            copy_frame(image, wrong)
    read_only = np.empty_like(image)
    read_only.flags.writeable = False
    with pytest.raises(ValueError, match="writable"):
        copy_frame(image, read_only)
    with pytest.raises(ValueError, match="BGR uint8 image"):
        copy_frame(image[:, :, 0], np.empty((240, 320), np.uint8))


def test_no_detections_gives_an_exact_copy() -> None:
    image = photo(320, 240)
    assert np.array_equal(annotate(image, []), image)


coordinate = st.floats(-300, 2300, allow_nan=False) | st.sampled_from([math.nan, math.inf])


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(coordinate, coordinate, coordinate, coordinate), max_size=6),
       st.sampled_from([(320, 240), (1920, 1080), (97, 61)]))
def test_the_kernel_draws_what_plain_numpy_slices_draw(
        boxes: list[tuple[float, float, float, float]], size: tuple[int, int]) -> None:
    """Boxes anywhere, partly or wholly outside the image, even NaN: never an error, and
    pixel for pixel what the slice-by-slice reference draws."""
    image = photo(*size, seed=len(boxes))
    detections = [person(box) for box in boxes]
    expected = reference(image, Overlay.of(size[0], size[1], detections))
    assert np.array_equal(annotate(image, detections), expected)
