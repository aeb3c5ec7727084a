"""Opening a camera source from a short description, as ``cyborg detect SOURCE`` takes it.

====================================  ==========================================================
SOURCE                                what is read
====================================  ==========================================================
``photo.png``                         one image (``--right``, ``--depth`` add its pair/depth)
``frames/``                           a folder of images (``left/``, ``right/``, ``depth/``
                                      subfolders are paired by file name)
``ride.mp4``                          a video file (``--side-by-side`` for ZED recordings)
``left.png,right.png``                a stereo pair of images, or of videos
``recording.bag``, ``rosbag2_dir/``   a ROS 1 bag, a ROS 2 bag (``.db3`` or ``.mcap``)
``camera:0`` (or ``0``)               a local camera through OpenCV
``bus:/cyborg/camera/left/image_raw``  camera topics on the bus (``--depth-topic``)
``sample:motorcycle``                 sample data from scikit-image (:mod:`.samples`)
====================================  ==========================================================
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from cyborg.vision.bag_source import BagSource, is_bag
from cyborg.vision.file_sources import DEFAULT_RATE, FolderSource, ImageSource, VideoSource
from cyborg.vision.frames import FrameSource, VisionError
from cyborg.vision.image_files import IMAGE_SUFFIXES, VIDEO_SUFFIXES
from cyborg.vision.samples import SampleSource


@dataclass(frozen=True)
class SourceOptions:
    """What a bare path cannot say: partners of an image, stereo packing, bag topics."""

    right: Path | None = None
    depth: Path | None = None
    side_by_side: bool = False
    rate: float = DEFAULT_RATE
    image_topic: str | None = None
    depth_topic: str | None = None
    right_topic: str | None = None


def camera_index(spec: str) -> int | None:
    """The device number of ``camera:N`` or ``N``, else None."""
    text = spec.removeprefix("camera:")
    # ASCII digits only: str.isdigit() also takes '²', which int() refuses
    return int(text) if text.isascii() and text.isdigit() else None


def anchored(spec: str, base: Path) -> str:
    """``spec`` with its file paths (both sides of a stereo pair) made absolute against ``base``.

    Cameras, samples and bus topics are left as they are.
    """
    if camera_index(spec) is not None or spec.startswith(("camera:", "sample:", "bus:")):
        return spec
    return ",".join(str((base / Path(part.strip()).expanduser()).resolve())
                    for part in spec.split(","))


def open_source(spec: str, options: SourceOptions | None = None) -> FrameSource:
    """The frame source ``spec`` names (see the module's table); :class:`VisionError` if none.

    A ``bus:`` source is opened by the caller, which owns a bus node.
    """
    options = options or SourceOptions()
    index = camera_index(spec)
    if index is not None:
        return VideoSource(index, side_by_side=options.side_by_side)
    if spec.startswith("camera:"):
        raise VisionError(f"{spec}: a camera is 'camera:N', N its device number (0, 1, ...)")
    if spec.startswith("sample:"):
        return SampleSource(spec.removeprefix("sample:"))
    if spec.startswith("bus:"):
        raise VisionError(f"{spec}: bus sources need a bus node (open them with BusSource)")
    if "," in spec and not Path(spec).exists():
        left_text, _, right_text = spec.partition(",")
        left, right = (Path(text.strip()).expanduser() for text in (left_text, right_text))
        if left.suffix.lower() in VIDEO_SUFFIXES:
            return VideoSource(left, right=right)
        return ImageSource(left, right=right, depth=options.depth)
    path = Path(spec).expanduser()
    if is_bag(path):
        return BagSource(path, image_topic=options.image_topic, depth_topic=options.depth_topic,
                         right_topic=options.right_topic)
    if path.is_dir():
        return FolderSource(path, rate=options.rate, side_by_side=options.side_by_side)
    if not path.exists():
        raise VisionError(f"source {spec}: not found (a file, folder, bag, 'camera:N', "
                          "'sample:NAME' or 'bus:TOPIC')")
    suffix = path.suffix.lower()
    if suffix in VIDEO_SUFFIXES:
        return VideoSource(path, side_by_side=options.side_by_side)
    if suffix in IMAGE_SUFFIXES:
        return ImageSource(path, right=options.right, depth=options.depth,
                           side_by_side=options.side_by_side)
    raise VisionError(f"source {spec}: unknown kind of file {suffix!r} (images: "
                      f"{', '.join(sorted(IMAGE_SUFFIXES))}; videos: "
                      f"{', '.join(sorted(VIDEO_SUFFIXES))}; bags: .bag, .db3, .mcap)")
