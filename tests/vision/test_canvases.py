"""Reusable buffers for the annotated image: one is reused only once nothing refers to it."""

from __future__ import annotations

import gc

import numpy as np

from cyborg.vision.canvases import Canvases
from cyborg.vision.detector import Detection, StageTimes
from cyborg.vision.frames import Frame
from cyborg.vision.pipeline import DetectionPipeline

SHAPE = (48, 64, 3)


def test_a_released_buffer_is_handed_out_again() -> None:
    canvases = Canvases()
    first = canvases.take(SHAPE)
    address = first.ctypes.data
    del first
    again = canvases.take(SHAPE)
    assert again.ctypes.data == address and again.shape == SHAPE and again.flags.writeable


def test_a_buffer_still_referred_to_is_never_handed_out() -> None:
    canvases = Canvases(keep=3)
    held = canvases.take(SHAPE)
    view = canvases.take(SHAPE).reshape(-1)[10:]  # only a view of the second survives
    window = canvases.take(SHAPE).data  # and a memoryview of the third
    fourth = canvases.take(SHAPE)
    freed = fourth.ctypes.data
    addresses = {held.ctypes.data, view.ctypes.data - 10,
                 np.frombuffer(window, np.uint8).ctypes.data, freed}
    assert len(addresses) == 4, "every live buffer is a different one"
    del fourth
    gc.collect()
    assert canvases.take(SHAPE).ctypes.data == freed  # the only one nobody holds
    del view, window
    assert canvases.take(SHAPE).ctypes.data in addresses - {held.ctypes.data}


def test_other_shapes_get_their_own_buffers_and_keep_bounds_the_pool() -> None:
    canvases = Canvases(keep=2)
    small = canvases.take((4, 4, 3))
    large = canvases.take((8, 8, 3))
    assert small.shape == (4, 4, 3) and large.shape == (8, 8, 3)
    held = [canvases.take(SHAPE) for _ in range(5)]
    assert len({buffer.ctypes.data for buffer in held}) == 5
    assert len(canvases._buffers) <= 2


def test_the_pipeline_never_draws_over_an_annotated_image_someone_keeps() -> None:
    class FixedDetector:
        """Stands in for the network: the same box on every frame, stage times zero."""

        def __init__(self) -> None:
            self.times = StageTimes()

        def detect(self, image: np.ndarray) -> list[Detection]:
            return [Detection("cup", 41, 0.9, (10.0, 20.0, 300.0, 200.0))]

    pipeline = DetectionPipeline(FixedDetector())  # type: ignore[arg-type]
    frames = [np.full((240, 320, 3), value, dtype=np.uint8) for value in (10, 90, 170)]
    kept = [pipeline.process(Frame(0, frame), draw=True).annotated for frame in frames]
    for value, annotated in zip((10, 90, 170), kept, strict=True):
        assert annotated is not None
        assert int(annotated[230, 310, 0]) == value, "each kept image shows its own frame"
    assert len({a.ctypes.data for a in kept if a is not None}) == 3
    del kept
    addresses = set()
    for frame in frames * 2:  # nothing kept: the pool's buffers are reused
        annotated = pipeline.process(Frame(0, frame), draw=True).annotated
        assert annotated is not None
        addresses.add(annotated.ctypes.data)
        del annotated
    assert len(addresses) <= 2
