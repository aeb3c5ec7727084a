"""Depth maps in metres: from a camera's depth image, or computed from a rectified stereo pair.

Depth follows REP 118: ``float32`` metres, where NaN, +inf and -inf keep their meanings
(unknown, too far, too close); ``uint16`` millimetres, where 0 means unknown. Both become
``float32`` metres here, with the unknown millimetre pixels as NaN.

A rectified stereo pair gives disparity ``d`` (pixels) with OpenCV's semi-global matcher, and
depth ``Z = f * B / (d + doffs)`` with the focal length ``f`` in pixels, the baseline ``B`` in
metres and ``doffs`` the difference of the two principal points' x (0 for a ZED, whose images
are rectified to one principal point; Middlebury's pairs give it)::

    stereo = StereoDepth(StereoCalibration(focal_px=700.0, baseline_m=0.12))
    depth = stereo.depth(left, right)      # float32 metres, NaN where no match
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from cyborg.vision.frames import VisionError, check_image


def depth_in_metres(depth: np.ndarray, what: str = "depth map") -> np.ndarray:
    """``float32`` metres from a float depth map (metres) or a ``uint16`` one (millimetres)."""
    if not isinstance(depth, np.ndarray) or depth.ndim != 2:
        raise VisionError(f"{what} must be a 2-D array, not {getattr(depth, 'shape', depth)!r}")
    if not depth.dtype.isnative:  # e.g. a big-endian .npy: same numbers, native order
        depth = depth.astype(depth.dtype.newbyteorder("="))
    if depth.dtype == np.uint16:
        metres = depth.astype(np.float32) * np.float32(0.001)
        metres[depth == 0] = np.nan
        return metres
    if depth.dtype in (np.float32, np.float64):
        return depth.astype(np.float32, copy=False)
    raise VisionError(f"{what} has type {depth.dtype}: depth must be float32 metres or uint16 "
                      "millimetres")


@dataclass(frozen=True)
class StereoCalibration:
    """What turns disparity into depth for a rectified pair."""

    focal_px: float
    baseline_m: float
    doffs_px: float = 0.0

    def __post_init__(self) -> None:
        if not self.focal_px > 0 or not self.baseline_m > 0:
            raise VisionError(f"stereo calibration needs a positive focal length and baseline, "
                              f"not f={self.focal_px} px, B={self.baseline_m} m")

    def depth_from_disparity(self, disparity: np.ndarray) -> np.ndarray:
        """Depth in metres of a disparity map (px), NaN where it gives none.

        NaN where the disparity is not positive or not finite, or, with a negative ``doffs``,
        where ``d + doffs`` is not positive: no depth is negative.
        """
        disparity = disparity.astype(np.float32, copy=False)
        shifted = disparity + np.float32(self.doffs_px)
        valid = np.isfinite(disparity) & (disparity > 0) & (shifted > 0)
        depth = np.full(disparity.shape, np.nan, dtype=np.float32)
        np.divide(np.float32(self.focal_px * self.baseline_m), shifted, out=depth, where=valid)
        return depth


class StereoDepth:
    """Depth from a rectified stereo pair with OpenCV's semi-global block matcher (SGBM_3WAY).

    ``max_disparity`` bounds the nearest object: ``Z_min = f * B / max_disparity``. SGBM_3WAY
    uses OpenCV's threads (``cv2.setNumThreads``); on a 2-core robot, run the detector's network
    with one thread beside it.
    """

    def __init__(self, calibration: StereoCalibration, *, max_disparity: int = 64,
                 block_size: int = 5) -> None:
        if max_disparity <= 0 or max_disparity % 16:
            raise VisionError(f"max_disparity must be a positive multiple of 16, not "
                              f"{max_disparity}")
        self.calibration = calibration
        channels = 3
        self.matcher = cv2.StereoSGBM.create(
            minDisparity=0, numDisparities=max_disparity, blockSize=block_size,
            P1=8 * channels * block_size ** 2, P2=32 * channels * block_size ** 2,
            disp12MaxDiff=1, uniquenessRatio=10, speckleWindowSize=100, speckleRange=2,
            mode=cv2.StereoSGBM_MODE_SGBM_3WAY)

    def disparity(self, left: np.ndarray, right: np.ndarray) -> np.ndarray:
        """Disparity in pixels (``float32``); NaN where the matcher found no match."""
        check_image(left, "left image")
        check_image(right, "right image")
        if left.shape != right.shape:
            raise VisionError(f"stereo pair of different sizes: left {left.shape[1]}x"
                              f"{left.shape[0]}, right {right.shape[1]}x{right.shape[0]}")
        fixed = self.matcher.compute(left, right)  # int16, 1/16 pixel; negative = no match
        disparity = fixed.astype(np.float32) * np.float32(1 / 16)
        disparity[fixed <= 0] = np.nan
        return disparity

    def depth(self, left: np.ndarray, right: np.ndarray) -> np.ndarray:
        """Depth in metres registered to the left image; NaN where unknown."""
        return self.calibration.depth_from_disparity(self.disparity(left, right))
