"""The annotated image: outlines, labels composed from the font's characters, and the copy."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.vision.annotate import (
    BOX_COLOUR,
    FONT,
    LABEL_GREY,
    Overlay,
    annotate,
    caption,
    copy_frame,
    draw_detections,
    line_sizes,
)
from cyborg.vision.detector import Detection
from cyborg.vision.glyphs import FIRST, GlyphFont, encode

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
    for index, (x0, y0, w, h) in enumerate(overlay.labels.tolist()):
        patch = label_patch(overlay.font, overlay.caption_codes(index), w, h)
        for y in range(max(y0, 0), min(y0 + h, height)):
            for x in range(max(x0, 0), min(x0 + w, width)):
                drawn[y, x] = patch[y - y0, x - x0]  # grey: all three channels
    return drawn


def label_patch(font: GlyphFont, codes: np.ndarray, width: int, height: int) -> np.ndarray:
    """A label composed with numpy: white, each character's cell at its pen (rounded), the
    darker grey wherever cells overlap."""
    canvas = np.full((height + 2 * font.cells.shape[1], width + 2 * font.cells.shape[2]),
                     LABEL_GREY, dtype=np.uint8)
    top, left = font.cells.shape[1:]  # the patch's origin in the canvas: room for any cell
    pen = 1.0
    for code in codes.tolist():
        cell = font.cells[code - FIRST]
        y, x = top + font.height + 1 - font.pen_y, left + round(pen) - font.pen_x
        region = canvas[y:y + cell.shape[0], x:x + cell.shape[1]]
        np.minimum(region, cell, out=region)
        pen += font.advances[code - FIRST]
    return canvas[top:top + height, left:left + width]


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
    label_x, _y, label_w, _h = Overlay.of(WIDTH, HEIGHT, [person((0, 0, 1, 1))]).labels[0]
    right_of_label = label_x + label_w + 100  # on the top edge, past the label over it
    assert right_of_label < 500
    for x, y in ((300, 900), (100, 600), (500, 600), (right_of_label, 200), (499, 899)):
        assert np.array_equal(annotated[y, x], green), (x, y)
    for x, y in ((300, 600), (50, 600), (600, 600), (300, 950), (103, 203)):
        assert np.array_equal(annotated[y, x], image[y, x]), (x, y)
    changed = np.any(annotated != image, axis=2)
    assert not changed[:150].any() and not changed[:, 510:].any() and not changed[910:].any()


def test_the_label_sits_above_the_box_with_its_caption() -> None:
    image = photo()
    detection = person((100.0, 200.0, 500.0, 900.0))
    overlay = Overlay.of(WIDTH, HEIGHT, [detection])
    x0, y0, w, h = overlay.labels[0].tolist()
    assert (x0, y0 + h - 1) == (100, 200) and w > 200 and 20 < h < 60
    label = annotate(image, [detection])[y0:y0 + h, x0:x0 + w]
    white = np.all(label == LABEL_GREY, axis=2).mean()
    dark = np.all(label < 100, axis=2).mean()
    assert white > 0.6 and dark > 0.03  # a white patch with black text on it


def _kerning(text: str, font: GlyphFont, scale: float) -> int:
    """How far OpenCV's width of ``text`` may stray from its characters' advances: the pixels
    by which it moves each pair of neighbours from where their advances put them (OpenCV 5.1
    kerns some pairs), plus one for rounding fractional advances (OpenCV 4)."""
    def alone(pair: str) -> float:
        return 1 + float(sum(font.advances[ord(character) - FIRST] for character in pair))
    return 1 + round(sum(abs(cv2.getTextSize(text[i:i + 2], FONT, scale, 1)[0][0]
                             - alone(text[i:i + 2])) for i in range(len(text) - 1)))


def _characters_side_by_side(text: str, font: GlyphFont, size: tuple[int, int],
                             origin: tuple[int, int]) -> np.ndarray:
    """A grey label with each character of ``text`` drawn by ``putText`` on its own, moved on
    from the last by the font's advance (the darker pixel where two characters meet)."""
    width, height = size
    margin = font.cells.shape[1]  # room for any character: OpenCV shades an edge it clips
    label = np.full((height + 2 * margin, width + 2 * margin), LABEL_GREY, dtype=np.uint8)
    pen = float(origin[0] + margin)
    for character in text:
        alone = np.full(label.shape, 255, dtype=np.uint8)
        cv2.putText(alone, character, (round(pen), origin[1] + margin), FONT, font.scale, 0, 1,
                    cv2.LINE_AA)
        np.minimum(label, alone, out=label)
        pen += font.advances[ord(character) - FIRST]
    return label[margin:margin + height, margin:margin + width]


def test_labels_are_sized_and_drawn_as_opencv_sizes_and_draws_text() -> None:
    """Each label is its caption's size plus a 1-pixel margin, the caption drawn character by
    character where the font's advances put them, pixel for pixel what ``putText`` draws of
    each character. Where OpenCV lays the caption out as its characters side by side (no
    kerned pairs), label and caption are ``getTextSize``'s and ``putText``'s own: pixel for
    pixel where the font advances by whole pixels (OpenCV 5.0), within half a pixel per
    character where it does not (OpenCV 4). OpenCV 5.1 kerns some pairs, moving its text by
    a pixel or a few: the label's width then differs from ``getTextSize``'s by no more."""
    image = np.full((HEIGHT, WIDTH, 3), 90, dtype=np.uint8)
    detections = [person((100.0, 200.0, 500.0, 900.0), distance=2.371),
                  Detection("motorcycle", 3, 0.5049, (900.0, 300.0, 1500.0, 700.0), math.nan),
                  Detection("bål|{~}", 80, 1.0, (40.0, 700.0, 80.0, 800.0), 12.0)]
    annotated = annotate(image, detections)
    overlay = Overlay.of(WIDTH, HEIGHT, detections)
    scale, _thickness = line_sizes(WIDTH, HEIGHT)
    font = overlay.font
    whole_pixels = np.array_equal(font.advances, np.round(font.advances))
    for (x0, y0, w, h), detection in zip(overlay.labels.tolist(), detections, strict=True):
        text = caption(detection).encode("ascii", "replace").decode()  # as the label shows it
        (text_w, text_h), baseline = cv2.getTextSize(text, FONT, scale, 1)
        label = annotated[y0:y0 + h, x0:x0 + w]
        assert np.array_equal(label[..., 0], label[..., 2])  # grey
        advances = 1 + sum(font.advances[ord(character) - FIRST] for character in text)
        assert (w, h) == (round(advances) + 3, text_h + baseline + 3), text
        kerning = _kerning(text, font, scale)
        assert abs(w - (text_w + 3)) <= kerning, text
        side_by_side = _characters_side_by_side(text, font, (w, h), (1, text_h + 1))
        assert np.array_equal(label[..., 0], side_by_side), text
        if text_w == round(advances):  # OpenCV too draws the characters side by side
            assert w == text_w + 3, text
            expected = np.full((h, w), LABEL_GREY, dtype=np.uint8)
            cv2.putText(expected, text, (1, text_h + 1), FONT, scale, 0, 1, cv2.LINE_AA)
            difference = np.abs(label[..., 0].astype(int) - expected)
            if whole_pixels:
                assert not difference.any(), text
            else:
                assert difference.mean() < 8, text


def test_captions_outside_printable_ascii_are_drawn_with_question_marks() -> None:
    codes, ends = encode(["bål", "a\tb", "", "ok"])
    assert codes.tobytes() == b"b?la?bok" and ends.tolist() == [3, 6, 6, 8]


def test_font_scales_that_are_not_positive_are_refused() -> None:
    with pytest.raises(ValueError, match="font scale must be positive, not 0"):
        GlyphFont.at(0.0)


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
