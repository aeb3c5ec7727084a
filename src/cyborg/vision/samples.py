"""Sample camera data that ships with scikit-image, for trying the detector without a camera.

``sample:motorcycle`` is the Middlebury 2014 "Motorcycle" stereo pair (Scharstein et al.,
GCPR 2014), downsampled to 741 x 500, with its ground-truth disparity turned into a depth map
in metres — what a calibrated stereo camera such as the ZED gives: left image, right image and
registered depth. Its calibration is :data:`MOTORCYCLE_CALIBRATION`, so a
:class:`~cyborg.vision.depth.StereoDepth` can compute depth from the pair as well.
``sample:astronaut`` and ``sample:camera`` are single photographs with a person (public domain
and CC0), without depth.
"""

from __future__ import annotations

from collections.abc import Iterator

import cv2
import numpy as np
from typing_extensions import override

from cyborg.vision.depth import StereoCalibration
from cyborg.vision.frames import Frame, FrameSource, VisionError
from cyborg.vision.image_files import as_bgr

MOTORCYCLE_CALIBRATION = StereoCalibration(focal_px=994.978, baseline_m=0.193001,
                                           doffs_px=31.086)
"""Focal length, baseline and principal-point offset of the downsampled Motorcycle pair."""

SAMPLES = ("motorcycle", "astronaut", "camera")


def motorcycle() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Left and right BGR images and the ground-truth depth in metres (NaN where unknown)."""
    from skimage import data

    left, right, disparity = data.stereo_motorcycle()  # type: ignore[no-untyped-call]
    # unknown disparities are +inf in this file; depth_from_disparity makes them NaN
    depth = MOTORCYCLE_CALIBRATION.depth_from_disparity(
        np.where(np.isfinite(disparity), disparity, np.nan).astype(np.float32))
    return (cv2.cvtColor(left, cv2.COLOR_RGB2BGR), cv2.cvtColor(right, cv2.COLOR_RGB2BGR),
            depth)


def photo(name: str) -> np.ndarray:
    """A scikit-image photograph as a BGR image."""
    from skimage import data

    image = getattr(data, name)()
    return as_bgr(image if image.ndim == 2 else cv2.cvtColor(image, cv2.COLOR_RGB2BGR),
                  f"sample:{name}")


class SampleSource(FrameSource):
    """One frame of a named sample (``motorcycle``, ``astronaut``, ``camera``)."""

    def __init__(self, name: str) -> None:
        super().__init__()
        if name not in SAMPLES:
            raise VisionError(f"sample:{name}: unknown sample; known: "
                              f"{', '.join(f'sample:{sample}' for sample in SAMPLES)}")
        try:
            import skimage  # noqa: F401
        except ImportError as exc:
            raise VisionError(f"sample:{name} needs scikit-image (pip install "
                              "scikit-image)") from exc
        self.sample, self.name, self.length = name, f"sample:{name}", 1

    @override
    def frames(self) -> Iterator[Frame]:
        if self.sample == "motorcycle":
            left, right, depth = motorcycle()
            yield Frame(0, left, right, depth, frame_id="middlebury_left")
        else:
            yield Frame(0, photo(self.sample), frame_id="camera")
