"""The detector: output layouts, non-maximum suppression, distances, the real model on real
photos and the Middlebury stereo oracle, and clear errors for bad models and inputs."""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.vision import DetectionPipeline, Detector, Frame, StereoDepth, VisionError
from cyborg.vision.backends import OnnxRuntimeBackend, OpenCvBackend
from cyborg.vision.distance import box_distance, box_distances, box_mean_2018
from cyborg.vision.layouts import (
    Layout,
    decode,
    grid_points,
    guess_layout,
    layout_named,
    yolox_grid,
)
from cyborg.vision.letterbox import InputFormat, Preprocessor
from cyborg.vision.samples import MOTORCYCLE_CALIBRATION, motorcycle, photo
from cyborg.vision.suppression import suppress

INPUT = (64, 64)


class FixedBackend:
    """A stand-in network that always returns the same output."""

    name = "fixed"

    def __init__(self, output: np.ndarray, input_hw: tuple[int, int] = INPUT) -> None:
        self.output, self.input_hw = output, input_hw
        self.metadata: dict[str, str] = {}

    def run(self, tensor: np.ndarray) -> np.ndarray:
        assert tensor.shape == (1, 3, *self.input_hw)
        return self.output


def v5_rows(*boxes: tuple[float, float, float, float, float, int], classes: int = 3,
            total: int = 0) -> np.ndarray:
    """A YOLOv5-style output: cx, cy, w, h, objectness, class probabilities."""
    rows = np.zeros((max(total, len(boxes)), 5 + classes), np.float32)
    for row, (cx, cy, w, h, score, class_id) in zip(rows, boxes, strict=False):
        row[:5] = cx, cy, w, h, 1.0
        row[5 + class_id] = score
    return rows[None]


@pytest.fixture(scope="module")
def model() -> Path:
    from tests.conftest import shared_dir
    return shared_dir() / "models" / "yolox_nano.onnx"


@pytest.fixture(scope="module")
def yolox(model: Path) -> Detector:
    return Detector.open(model, threads=2)


# ------------------------------------------------------------------ layouts
def test_every_layout_decodes_to_the_same_box() -> None:
    """One object at centre (32, 24), 16 x 8 pixels, class 2, score 0.8, in each family's form."""
    hw = INPUT
    v5 = v5_rows((32, 24, 16, 8, 0.8, 2))
    v8 = np.zeros((1, 4 + 3, 10), np.float32)
    v8[0, :4, 7] = 32, 24, 16, 8
    v8[0, 4 + 2, 7] = 0.8
    end2end = np.zeros((1, 300, 6), np.float32)
    end2end[0, 5] = 24, 20, 40, 28, 0.8, 2
    darknet = np.zeros((4, 8), np.float32)
    darknet[1] = 32 / 64, 24 / 64, 16 / 64, 8 / 64, 0.9, 0, 0, 0.8
    yolox = np.zeros((1, grid_points(hw), 8), np.float32)
    # stride-8 grid cell (4, 3): centre = (raw + cell) * 8 = (32, 24); size = exp(raw) * 8
    yolox[0, 3 * 8 + 4, :5] = 0.0, 0.0, math.log(2), 0.0, 1.0
    yolox[0, 3 * 8 + 4, 5 + 2] = 0.8
    for layout, output in ((Layout.YOLOV5, v5), (Layout.YOLOV8, v8), (Layout.END2END, end2end),
                           (Layout.DARKNET, darknet), (Layout.YOLOX, yolox)):
        found = decode(layout, output, hw, 0.5)
        assert len(found) == 1, layout
        assert found.boxes[0] == pytest.approx([24, 20, 40, 28], abs=1e-4), layout
        assert found.scores[0] == pytest.approx(0.8) and found.class_ids[0] == 2, layout


def test_the_layout_is_told_by_the_output_shape() -> None:
    assert guess_layout((1, 84, 8400), 80, (640, 640)) is Layout.YOLOV8
    assert guess_layout((1, 300, 6), 80, (640, 640)) is Layout.END2END
    assert guess_layout((1, 25200, 85), 80, (640, 640)) is Layout.YOLOV5
    assert guess_layout((1, 3549, 85), 80, (416, 416), "yolox_nano.onnx") is Layout.YOLOX
    assert layout_named("yolo11") is Layout.YOLOV8 and layout_named("YOLOv7") is Layout.YOLOV5
    with pytest.raises(VisionError, match="raw YOLOX head and a decoded YOLOv6"):
        guess_layout((1, 8400, 85), 80, (640, 640), "model.onnx")
    with pytest.raises(VisionError, match=r"unknown output layout \[1, 2, 3, 4\]"):
        guess_layout((1, 2, 3, 4), 80, (640, 640), "odd.onnx")
    with pytest.raises(VisionError, match="unknown output layout"):
        guess_layout((1, 1000, 90), 80, (640, 640))
    with pytest.raises(VisionError, match="12 classes do not match the 80 labels"):
        guess_layout((1, 16, 8400), 80, (640, 640))
    with pytest.raises(VisionError, match="unknown detector family 'yolo99'"):
        layout_named("yolo99")


def test_an_unknown_output_layout_is_a_clear_error_at_load() -> None:
    with pytest.raises(VisionError, match=r"unknown output layout \[1, 7, 7, 7\]"):
        Detector(FixedBackend(np.zeros((1, 7, 7, 7), np.float32)), model_name="odd.onnx")
    with pytest.raises(VisionError, match="anchor points"):
        Detector(FixedBackend(np.zeros((1, 100, 85), np.float32)), layout=Layout.YOLOX)
    with pytest.raises(VisionError, match=r"narrow.onnx: output \[1, 100, 5\] does not fit "
                                          r"the yolov5 layout \(5 columns"):
        Detector(FixedBackend(np.zeros((1, 100, 5), np.float32)), layout=Layout.YOLOV5,
                 model_name="narrow.onnx")


# ------------------------------------------------------------------ non-maximum suppression
def test_overlapping_boxes_of_one_class_collapse_but_other_classes_stay() -> None:
    """The 2018 node published every duplicate; here one box per object and class remains."""
    output = v5_rows((32, 32, 20, 20, 0.9, 0), (33, 32, 20, 20, 0.85, 0),
                     (32, 33, 20, 21, 0.7, 0), (32, 32, 20, 20, 0.8, 1),
                     (8, 8, 6, 6, 0.6, 0), total=50)
    detector = Detector(FixedBackend(output), layout=Layout.YOLOV5, labels=("a", "b", "c"),
                        confidence=0.5)
    raw = decode(Layout.YOLOV5, output, INPUT, 0.5)
    assert len(raw) == 5
    found = detector.detect(np.zeros((64, 64, 3), np.uint8))
    assert [(d.label, round(d.confidence, 2)) for d in found] == [("a", 0.9), ("b", 0.8),
                                                                   ("a", 0.6)]
    detector.classes = frozenset({"b"})
    assert [d.label for d in detector.detect(np.zeros((64, 64, 3), np.uint8))] == ["b"]
    detector.classes, detector.confidence = frozenset(), 0.95
    assert detector.detect(np.zeros((64, 64, 3), np.uint8)) == []


boxes_strategy = st.lists(
    st.tuples(st.integers(0, 60), st.integers(0, 60), st.integers(1, 30), st.integers(1, 30),
              st.sampled_from([0.3, 0.5, 0.55, 0.7, 0.9]), st.integers(0, 2)),
    max_size=40)


@settings(max_examples=200, deadline=None)
@given(boxes_strategy, st.sampled_from([0.0, 0.3, 0.45, 0.7]))
def test_suppression_keeps_what_opencv_keeps(boxes: list[tuple[int, int, int, int, float, int]],
                                             iou: float) -> None:
    """OpenCV's batched NMS is the oracle: the same boxes kept, in the same order (ties in
    score included: the earlier box wins)."""
    xywh = np.array([b[:4] for b in boxes], np.float32).reshape(-1, 4)
    scores = np.array([b[4] for b in boxes], np.float32)
    class_ids = np.array([b[5] for b in boxes], np.int32)
    corners = xywh.copy()
    corners[:, 2:] += corners[:, :2]
    ours = suppress(corners, scores, class_ids, iou=iou, limit=100).tolist()
    theirs = [int(i) for i in np.asarray(cv2.dnn.NMSBoxesBatched(
        xywh.astype(np.float64).tolist(), scores.tolist(), class_ids.tolist(), 0.0, iou)
        ).reshape(-1)]
    assert ours == theirs


def test_suppression_limits_and_rejects_mismatched_inputs() -> None:
    boxes = np.array([[0, 0, 10, 10], [20, 20, 30, 30], [40, 40, 50, 50]], np.float32)
    scores = np.array([0.5, 0.9, 0.7], np.float32)
    classes = np.zeros(3, np.int32)
    assert suppress(boxes, scores, classes, iou=0.5, limit=2).tolist() == [1, 2]
    assert suppress(boxes, scores, classes, iou=0.5, limit=0).tolist() == []
    with pytest.raises(ValueError, match="3 boxes, 2 scores and 3 class ids"):
        suppress(boxes, scores[:2], classes, iou=0.5)


def numpy_decode(layout: Layout, output: np.ndarray, input_hw: tuple[int, int],
                 threshold: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The YOLOX / YOLOv5 decoding written out in numpy, the reference for the compiled one."""
    rows = output.reshape(-1, output.shape[-1]).astype(np.float64)
    if layout is Layout.YOLOX:
        cells, strides = yolox_grid(input_hw)
        centres = np.concatenate([(rows[:, :2] + cells) * strides,
                                  np.exp(rows[:, 2:4]) * strides], axis=1)
    else:
        centres = rows[:, :4]
    class_ids = rows[:, 5:].argmax(axis=1)
    scores = rows[:, 4] * rows[np.arange(len(rows)), 5 + class_ids]
    keep = (rows[:, 4] >= threshold) & (scores >= threshold)
    boxes = np.concatenate([centres[:, :2] - centres[:, 2:] / 2,
                            centres[:, :2] + centres[:, 2:] / 2], axis=1)
    return boxes[keep], scores[keep], class_ids[keep]


@pytest.mark.parametrize("layout", [Layout.YOLOX, Layout.YOLOV5])
def test_the_compiled_decoding_matches_numpy(layout: Layout) -> None:
    rng = np.random.default_rng(3)
    rows = grid_points(INPUT) * (1 if layout is Layout.YOLOX else 3)
    output = rng.uniform(0, 1, (1, rows, 85)).astype(np.float32)
    output[..., :4] = rng.uniform(-1, 3, (1, rows, 4))
    candidates = decode(layout, output, INPUT, 0.5)
    boxes, scores, class_ids = numpy_decode(layout, output, INPUT, 0.5)
    assert len(candidates) == len(scores) > 10
    assert candidates.boxes == pytest.approx(boxes, rel=1e-5, abs=1e-4)
    assert candidates.scores == pytest.approx(scores, rel=1e-6)
    assert candidates.class_ids.tolist() == class_ids.tolist()
    read_only = output.copy()
    read_only.flags.writeable = False  # frames from the bus are read-only views
    assert len(decode(layout, read_only, INPUT, 0.5)) == len(scores)


def test_the_yolov8_decoding_matches_the_per_anchor_reference() -> None:
    """Reducing over classes along the output's rows gives what a per-anchor argmax gives."""
    rng = np.random.default_rng(4)
    anchors = grid_points(INPUT)
    output = rng.uniform(0, 0.6, (1, 4 + 80, anchors)).astype(np.float32)
    output[0, :4] = rng.uniform(0, 64, (4, anchors))
    rows = output[0].T
    class_ids = rows[:, 4:].argmax(axis=1)
    scores = rows[np.arange(anchors), 4 + class_ids]
    keep = scores >= 0.55
    candidates = decode(Layout.YOLOV8, output, INPUT, 0.55)
    assert len(candidates) == keep.sum() > 10
    assert candidates.scores.tolist() == scores[keep].tolist()
    assert candidates.class_ids.tolist() == class_ids[keep].tolist()
    centres = rows[keep, :4]
    assert candidates.boxes[:, :2] == pytest.approx(centres[:, :2] - centres[:, 2:] / 2)


def test_boxes_map_back_through_the_letterbox() -> None:
    """A 128 x 64 image in a 64 x 64 input: scale 1/2, centred with 16 px of padding on top."""
    output = v5_rows((32, 32, 16, 16, 0.9, 0))
    detector = Detector(FixedBackend(output), layout=Layout.YOLOV5, labels=("a",))
    (found,) = detector.detect(np.zeros((64, 128, 3), np.uint8))
    # input box (24, 24)-(40, 40), less the offset (0, 16), doubled
    assert found.box == pytest.approx((48, 16, 80, 48), abs=1e-4)
    assert found.corners == ((48, 16), (80, 16), (80, 48), (48, 48))


def test_boxes_reaching_into_the_padding_are_clipped_to_the_image() -> None:
    """Same letterbox: one box over the top-left corner, one over the bottom-right one."""
    output = v5_rows((4, 20, 24, 24, 0.9, 0), (60, 60, 16, 16, 0.8, 0))
    detector = Detector(FixedBackend(output), layout=Layout.YOLOV5, labels=("a",))
    first, second = detector.detect(np.zeros((64, 128, 3), np.uint8))
    assert first.box == pytest.approx((0, 0, 32, 32), abs=1e-4)
    assert second.box == pytest.approx((104, 64, 128, 64), abs=1e-4)


def test_the_input_tensor_follows_the_family() -> None:
    image = np.zeros((20, 40, 3), np.uint8)
    image[:, :] = (10, 20, 30)  # B, G, R
    bgr, _ = Preprocessor((40, 40), InputFormat())(image)
    assert bgr[0, :, 0, 0].tolist() == [10, 20, 30] and bgr[0, 0, 39, 0] == 114  # padded below
    rgb, box = Preprocessor((40, 40), InputFormat(rgb=True, scale=1 / 255, centred=True))(image)
    assert rgb[0, :, 20, 0] == pytest.approx([30 / 255, 20 / 255, 10 / 255])
    assert rgb[0, 0, 0, 0] == pytest.approx(114 / 255) and box.offset_y == 10


@pytest.mark.parametrize("input_format", [InputFormat(), InputFormat(rgb=True, scale=1 / 255,
                                                                     centred=True)])
def test_the_input_tensor_is_the_letterboxed_image_frame_after_frame(
        input_format: InputFormat) -> None:
    """Against a plain numpy reference, for several frames in a row and a change of size (the
    preprocessor reuses its buffers between calls)."""
    preprocess = Preprocessor((64, 96), input_format)
    rng = np.random.default_rng(3)
    for shape in ((120, 200, 3), (120, 200, 3), (90, 60, 3), (120, 200, 3)):
        image = rng.integers(0, 256, shape, dtype=np.uint8)
        tensor, box = preprocess(image)
        resized = cv2.resize(image, (round(shape[1] * box.scale), round(shape[0] * box.scale)),
                             interpolation=cv2.INTER_LINEAR)
        planes = resized.transpose(2, 0, 1)[::-1] if input_format.rgb else \
            resized.transpose(2, 0, 1)
        expected = np.full((1, 3, 64, 96), 114 * input_format.scale, dtype=np.float32)
        expected[0, :, box.offset_y:box.offset_y + resized.shape[0],
                 box.offset_x:box.offset_x + resized.shape[1]] = planes * np.float32(
                     input_format.scale)
        assert np.array_equal(tensor, expected), shape


# ------------------------------------------------------------------ distance
def test_distance_is_the_median_of_valid_depth_and_never_zero() -> None:
    depth = np.full((100, 200), 3.0, np.float32)
    depth[40:60, 120:180] = 1.5  # an object in the right half, away from the diagonal
    depth[45, 130:140] = np.nan
    depth[50, 130:140] = np.inf
    depth[55, 130:140] = 0.0
    distance, fraction = box_distance(depth, (110.0, 30.0, 190.0, 70.0))
    assert distance == pytest.approx(1.5) and 0.8 < fraction < 1.0
    # the 2018 slice depth[x1:x2, y1:y2] reads rows 110..190 of a 100-row map: nothing
    assert depth[110:190, 30:70].size == 0
    unknown = np.full((100, 200), np.nan, np.float32)
    unknown[::2] = 0.0
    distance, fraction = box_distance(unknown, (10.0, 10.0, 90.0, 90.0))
    assert math.isnan(distance) and fraction == 0.0
    assert box_distance(depth, (250.0, 10.0, 260.0, 20.0))[0] != 0.0  # outside: NaN, not 0
    assert math.isnan(box_distance(depth, (250.0, 10.0, 260.0, 20.0))[0])



def test_distances_of_many_boxes_at_once() -> None:
    """One pass over all boxes gives what each box gives alone, on read-only and strided maps,
    and the median of every valid pixel where the box is small enough to take them all."""
    rng = np.random.default_rng(5)
    depth = rng.uniform(0.5, 8.0, (120, 160)).astype(np.float32)
    depth[rng.uniform(size=depth.shape) < 0.2] = np.nan
    boxes = np.array([[10, 10, 50, 40], [0, 0, 160, 120], [150, 110, 400, 300],
                      [-20, -20, -5, -5], [30, 30, 31, 31], [np.nan, 0, 10, 10]], np.float64)
    together = box_distances(depth, boxes, inner=0.6)
    for box, (median, share) in zip(boxes[:5], together[:5], strict=True):
        alone = box_distance(depth, tuple(box), inner=0.6)
        assert (median, share) == pytest.approx(alone, nan_ok=True)
    inside = depth[16:34, 18:42]  # the first box's middle 60 %, every pixel (no stride)
    assert together[0, 0] == pytest.approx(np.nanmedian(inside))
    assert together[0, 1] == pytest.approx(np.isfinite(inside).mean())
    assert math.isnan(together[3, 0]) and together[3, 1] == 0.0  # outside the image
    assert math.isnan(together[5, 0])  # a box without coordinates has no distance
    frozen = depth.copy()
    frozen.flags.writeable = False  # depth from the bus is a read-only view
    assert box_distances(frozen, boxes, inner=0.6)[:3] == pytest.approx(together[:3], nan_ok=True)
    wide = np.zeros((120, 320), np.float32)
    wide[:, ::2] = depth  # a strided view
    strided = box_distances(wide[:, ::2], boxes, inner=0.6)
    assert strided[:3] == pytest.approx(together[:3], nan_ok=True)
    with pytest.raises(ValueError, match="inner must be in"):
        box_distances(depth, boxes, inner=0.0)
    with pytest.raises(ValueError, match="2-D"):
        box_distances(depth[None], boxes)
    with pytest.raises(ValueError, match="samples must be at least 1, not 0"):
        box_distances(depth, boxes, samples=0)


def test_a_small_box_is_sampled_densely_enough() -> None:
    depth = np.full((50, 50), 2.0, np.float32)
    depth[20:24, 20:24] = 0.7
    distance, fraction = box_distance(depth, (20.0, 20.0, 24.0, 24.0), inner=1.0)
    assert distance == pytest.approx(0.7) and fraction == 1.0


# ------------------------------------------------------------------ the real model
def test_the_person_in_the_photographs_is_found(yolox: Detector) -> None:
    for name in ("astronaut", "camera"):
        found = yolox.detect(photo(name))
        assert found and found[0].label == "person" and found[0].confidence > 0.85, name
        x1, y1, x2, y2 = found[0].box
        assert x2 - x1 > 200 and y2 - y1 > 350, name


def test_motorcycle_distance_from_stereo_matches_ground_truth(yolox: Detector) -> None:
    """Middlebury Motorcycle: depth computed by SGBM inside the detected box is within 5 % of
    the ground-truth median (measured: 2.368 m against 2.377 m)."""
    left, right, truth = motorcycle()
    pipeline = DetectionPipeline(yolox, stereo=StereoDepth(MOTORCYCLE_CALIBRATION))
    original = left.copy()
    result = pipeline.process(Frame(0, left, right), draw=True)
    assert np.array_equal(left, original), "the frame itself is never drawn on"
    assert pipeline.process(Frame(0, left, right)).detections == result.detections
    bikes = [d for d in result.detections if d.label == "motorcycle"]
    assert len(bikes) == 1 and bikes[0].confidence > 0.8
    expected, _ = box_distance(truth, bikes[0].box, samples=10**7)
    assert expected == pytest.approx(2.376, abs=0.01)
    assert bikes[0].distance == pytest.approx(expected, rel=0.05)
    assert bikes[0].depth_fraction > 0.85
    # the 2018 full-box mean is pulled away by the background behind the motorcycle
    assert abs(box_mean_2018(truth, bikes[0].box) - expected) > 0.1
    assert result.annotated is not None and result.annotated.shape == left.shape
    assert not np.array_equal(result.annotated, left)
    assert set(result.times) == {"depth", "preprocess", "inference", "postprocess", "distance",
                                 "drawing"}


def test_the_network_finds_one_motorcycle_where_the_raw_output_has_many(yolox: Detector
                                                                          ) -> None:
    left, _, _ = motorcycle()
    tensor, _ = yolox.preprocessor(left)
    raw = decode(yolox.layout, yolox.backend.run(tensor), yolox.input_hw, 0.5)
    assert int((raw.class_ids == 3).sum()) > 3, "the raw head proposes the bike many times"
    assert [d.label for d in yolox.detect(left)].count("motorcycle") == 1


def test_opencv_dnn_gives_the_same_detections(model: Path, yolox: Detector) -> None:
    opencv = Detector(OpenCvBackend(model, threads=1), model_name=model.name)
    image = photo("astronaut")
    ours, theirs = yolox.detect(image), opencv.detect(image)
    assert [d.label for d in ours] == [d.label for d in theirs]
    assert ours[0].box == pytest.approx(theirs[0].box, abs=1.0)


# ------------------------------------------------------------------ bad models and inputs
def test_missing_and_corrupt_models_are_clear_errors(tmp_path: Path) -> None:
    with pytest.raises(VisionError, match=r"model file .*nothere.onnx: not found"):
        Detector.open(tmp_path / "nothere.onnx")
    corrupt = tmp_path / "corrupt.onnx"
    corrupt.write_bytes(b"\x08\x07garbage" * 100)
    with pytest.raises(VisionError, match=r"corrupt.onnx cannot be loaded by onnxruntime"):
        Detector.open(corrupt)
    with pytest.raises(VisionError, match=r"corrupt.onnx cannot be loaded by OpenCV"):
        Detector.open(corrupt, backend="opencv")
    with pytest.raises(VisionError, match="unknown backend 'tensorflow'"):
        Detector.open(corrupt, backend="tensorflow")
    cfg, weights = tmp_path / "yolov3.cfg", tmp_path / "yolov3.weights"
    cfg.write_text("[net]\nwidth=416\nheight=416\n[yolo]\nclasses=80\n")
    weights.write_bytes(b"\0" * 64)
    with pytest.raises(VisionError, match=r"needs its \.weights file"):
        Detector.open(cfg)
    if not hasattr(cv2.dnn, "readNetFromDarknet"):  # OpenCV 5: the importer is gone
        with pytest.raises(VisionError, match="OpenCV 5 removed the importer"):
            Detector.open(cfg, weights=weights)
    else:  # OpenCV 4: the file is read, and these weights are too short
        with pytest.raises(VisionError, match=r"yolov3\.cfg"):
            Detector.open(cfg, weights=weights)


def test_bad_images_and_depth_maps_are_refused_with_the_reason(yolox: Detector) -> None:
    with pytest.raises(VisionError, match="BGR uint8 array"):
        yolox.detect(np.zeros((10, 10), np.float32))
    left = np.zeros((50, 80, 3), np.uint8)
    with pytest.raises(VisionError, match="depth map is 40x50 but the image is 80x50"):
        Frame(0, left, depth=np.zeros((50, 40), np.float32))
    with pytest.raises(VisionError, match="stereo pair must have one size"):
        Frame(0, left, right=np.zeros((50, 81, 3), np.uint8))


def test_labels_from_a_file(tmp_path: Path, model: Path) -> None:
    labels = tmp_path / "names.txt"
    labels.write_text("# my classes\n" + "\n".join(f"thing{i}" for i in range(80)) + "\n")
    detector = Detector.open(model, labels=labels)
    assert detector.detect(photo("astronaut"))[0].label == "thing0"
    (tmp_path / "empty.txt").write_text("\n# nothing\n")
    with pytest.raises(VisionError, match="has no class names"):
        Detector.open(model, labels=tmp_path / "empty.txt")


def test_backend_reads_the_input_size(model: Path) -> None:
    backend = OnnxRuntimeBackend(model, threads=1)
    assert backend.input_hw == (416, 416)
    with pytest.raises(VisionError, match="takes 416x416 input, not the 640"):
        OnnxRuntimeBackend(model, input_size=640)
