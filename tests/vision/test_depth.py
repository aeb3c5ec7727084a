"""Depth in metres (cyborg.vision.depth): conversions, disparity and stereo matching.

Millimetres and float64 metres become float32 metres with NaN where unknown; a stereo
calibration turns disparity into depth (never a negative one); and StereoDepth measures the
depth of a synthetic rectified pair, refusing bad input.
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from cyborg.vision import StereoCalibration, StereoDepth, VisionError, depth_in_metres
from tests.vision.source_fixtures import same_depth, texture


def test_depth_in_metres() -> None:
    millimetres = np.array([[0, 1, 1234], [65535, 500, 0]], np.uint16)
    same_depth(depth_in_metres(millimetres),
               np.array([[np.nan, 0.001, 1.234], [65.535, 0.5, np.nan]]))
    metres64 = np.array([[1.5, np.nan], [np.inf, -np.inf]])
    converted = depth_in_metres(metres64)
    assert converted.dtype == np.float32
    np.testing.assert_array_equal(converted, metres64.astype(np.float32))
    metres32 = np.ones((2, 2), np.float32)
    assert depth_in_metres(metres32) is metres32  # no copy of what is already right
    for bad in (np.ones((2, 2), np.int32), np.ones((2, 2), np.uint8),
                np.ones((2, 2), np.float16)):
        with pytest.raises(VisionError, match=f"the depth has type {bad.dtype}"):
            depth_in_metres(bad, "the depth")
    with pytest.raises(VisionError, match="2-D"):
        depth_in_metres(np.ones(4, np.float32))


def test_depth_from_disparity() -> None:
    calibration = StereoCalibration(focal_px=700.0, baseline_m=0.12)
    disparity = np.array([[84.0, 42.0, 0.0], [-3.0, np.nan, np.inf]], np.float32)
    depth = calibration.depth_from_disparity(disparity)
    np.testing.assert_allclose(depth[0, :2], [1.0, 2.0], rtol=1e-6)
    assert np.isnan(depth[0, 2]) and np.isnan(depth[1]).all()
    shifted = StereoCalibration(focal_px=700.0, baseline_m=0.12, doffs_px=16.0)
    np.testing.assert_allclose(shifted.depth_from_disparity(np.array([[68.0]])), [[1.0]],
                               rtol=1e-6)
    behind = StereoCalibration(focal_px=700.0, baseline_m=0.12, doffs_px=-16.0)
    depth = behind.depth_from_disparity(np.array([[100.0, 16.0, 10.0]]))
    np.testing.assert_allclose(depth[0, 0], 1.0, rtol=1e-6)
    assert np.isnan(depth[0, 1:]).all()  # d + doffs <= 0: no depth, never a negative one
    for focal, baseline in ((0.0, 0.1), (500.0, -0.1), (float("nan"), 0.1)):
        with pytest.raises(VisionError, match="positive focal length and baseline"):
            StereoCalibration(focal_px=focal, baseline_m=baseline)


def shifted_pair(height: int, width: int, background: int, near: int,
                 box: tuple[int, int, int, int]) -> tuple[np.ndarray, np.ndarray]:
    """A rectified pair: the background ``background`` pixels apart, a box ``near`` apart.

    A point at column ``x`` of the left image is at ``x - disparity`` in the right one.
    """
    far = cv2.GaussianBlur(texture(height, width + background, 11), (3, 3), 0)
    close = cv2.GaussianBlur(texture(height, width, 12), (3, 3), 0)
    top, bottom, x0, x1 = box
    left = far[:, :width].copy()
    left[top:bottom, x0:x1] = close[top:bottom, x0:x1]
    right = far[:, background:width + background].copy()
    right[top:bottom, x0 - near:x1 - near] = close[top:bottom, x0:x1]
    return left, right


def test_stereo_depth_of_a_synthetic_pair() -> None:
    calibration = StereoCalibration(focal_px=500.0, baseline_m=0.1)
    box = (40, 90, 100, 160)
    left, right = shifted_pair(120, 200, 8, 24, box)
    stereo = StereoDepth(calibration, max_disparity=64)
    depth = stereo.depth(left, right)
    assert depth.shape == (120, 200) and depth.dtype == np.float32
    top, bottom, x0, x1 = box
    near = float(np.nanmedian(depth[top + 4:bottom - 4, x0 + 4:x1 - 4]))
    assert near == pytest.approx(500.0 * 0.1 / 24, rel=0.02)
    far = float(np.nanmedian(depth[4:top - 4, 70:196]))
    assert far == pytest.approx(500.0 * 0.1 / 8, rel=0.02)
    assert np.isnan(depth[:, :8]).all()  # no match left of the widest disparity


def test_stereo_depth_refuses_bad_input() -> None:
    calibration = StereoCalibration(focal_px=500.0, baseline_m=0.1)
    for bad in (0, 24, -16):
        with pytest.raises(VisionError, match="multiple of 16"):
            StereoDepth(calibration, max_disparity=bad)
    stereo = StereoDepth(calibration)
    with pytest.raises(VisionError, match="different sizes"):
        stereo.depth(texture(8, 8, 0), texture(8, 10, 0))
    with pytest.raises(VisionError, match="right image must be a BGR"):
        stereo.depth(texture(8, 8, 0), np.zeros((8, 8), np.uint8))
