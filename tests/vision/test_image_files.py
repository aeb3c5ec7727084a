"""Images and depth maps read from files (cyborg.vision.image_files), through ImageSource.

Grey, BGRA and 16-bit images become BGR uint8; depth maps in millimetres (16-bit PNG) or metres
(.npy, .npz, float64, big-endian) become float32 metres with NaN where unknown; corrupt or
truncated images and depth maps of the wrong type are refused with errors that name the file.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest

from cyborg.vision import VisionError
from cyborg.vision.file_sources import FolderSource, ImageSource
from tests.vision.source_fixtures import (
    frames_of,
    same_depth,
    texture,
    write_image,
    write_npy,
)


def test_depth_png_in_millimetres_becomes_metres_with_zero_as_nan(tmp_path: Path) -> None:
    millimetres = np.array([[0, 1500, 65535], [250, 0, 1]], dtype=np.uint16)
    write_image(tmp_path / "depth.png", millimetres)
    [frame] = frames_of(ImageSource(write_image(tmp_path / "image.png", texture(2, 3, 0)),
                                    depth=tmp_path / "depth.png"))
    same_depth(frame.depth, np.array([[np.nan, 1.5, 65.535], [0.25, np.nan, 0.001]]))


def test_depth_npz_and_float64_npy_are_read_as_float32_metres(tmp_path: Path) -> None:
    metres = np.array([[1.25, 2.5], [np.nan, np.inf]])
    np.savez(tmp_path / "d.npz", depth=metres)
    write_npy(tmp_path / "d.npy", metres)  # float64
    shutil.copy(tmp_path / "d.npy", tmp_path / "UPPER.NPY")
    image = write_image(tmp_path / "i.png", texture(2, 2, 0))
    for name in ("d.npz", "d.npy", "UPPER.NPY"):
        [frame] = frames_of(ImageSource(image, depth=tmp_path / name))
        same_depth(frame.depth, metres)


def test_grey_bgra_and_16_bit_images_become_bgr_uint8(tmp_path: Path) -> None:
    grey = np.arange(12, dtype=np.uint8).reshape(3, 4) * 20
    bgra = np.dstack([texture(3, 4, 5), np.full((3, 4), 7, np.uint8)])
    deep = (texture(3, 4, 6).astype(np.uint16) << 8) | 0xFF
    [from_grey] = frames_of(ImageSource(write_image(tmp_path / "grey.png", grey)))
    [from_bgra] = frames_of(ImageSource(write_image(tmp_path / "bgra.png", bgra)))
    [from_deep] = frames_of(ImageSource(write_image(tmp_path / "deep.png", deep)))
    np.testing.assert_array_equal(from_grey.left, np.dstack([grey] * 3))
    np.testing.assert_array_equal(from_bgra.left, bgra[:, :, :3])
    np.testing.assert_array_equal(from_deep.left, texture(3, 4, 6))


def test_corrupt_and_truncated_images_are_named(tmp_path: Path) -> None:
    noise = tmp_path / "noise.png"
    noise.write_bytes(np.random.default_rng(1).bytes(400))
    whole = cv2.imencode(".png", texture(20, 20, 0))[1].tobytes()
    truncated = tmp_path / "truncated.png"
    truncated.write_bytes(whole[: len(whole) // 2])
    for path in (noise, truncated):
        with pytest.raises(VisionError, match=rf"image .*{path.name}: cannot be decoded"):
            ImageSource(path)
    with pytest.raises(VisionError, match="is a folder"):
        ImageSource(tmp_path)
    write_image(tmp_path / "folder" / "0.png", texture(2, 2, 0))
    noise.rename(tmp_path / "folder" / "1.png")
    with pytest.raises(VisionError, match=r"1\.png: cannot be decoded"):
        frames_of(FolderSource(tmp_path / "folder"))


def test_depth_maps_of_wrong_type_are_refused(tmp_path: Path) -> None:
    image = write_image(tmp_path / "image.png", texture(2, 2, 0))
    cases = {"int.npy": r"int32: depth must be float32 metres or uint16",
             "grey.png": r"uint8 pixels",
             "cube.npy": r"must be a 2-D array",
             "broken.npy": r"not a readable numpy array",
             "objects.npy": r"not a readable numpy array"}
    write_npy(tmp_path / "int.npy", np.ones((2, 2), np.int32))
    write_image(tmp_path / "grey.png", np.ones((2, 2), np.uint8))
    write_npy(tmp_path / "cube.npy", np.ones((2, 2, 2), np.float32))
    (tmp_path / "broken.npy").write_bytes(b"\x93NUMPY garbage")
    np.save(tmp_path / "objects.npy", np.array([[None, 1]], dtype=object), allow_pickle=True)
    for name, message in cases.items():
        with pytest.raises(VisionError, match=message):
            frames_of(ImageSource(image, depth=tmp_path / name))


def test_big_endian_depth_npy_is_read(tmp_path: Path) -> None:
    image = write_image(tmp_path / "image.png", texture(1, 2, 0))
    write_npy(tmp_path / "depth.npy", np.array([[0, 1250]], dtype=">u2"))
    [frame] = frames_of(ImageSource(image, depth=tmp_path / "depth.npy"))
    same_depth(frame.depth, np.array([[np.nan, 1.25]]))
