"""Class names: the 80 COCO classes the bundled models know, or a label file of the user's.

A label file has one class name per line, in the network's class order; blank lines and lines
starting with ``#`` are skipped (Darknet's ``coco.names`` reads as it is).
"""

from __future__ import annotations

from pathlib import Path

from cyborg.vision.frames import VisionError

COCO = (
    "person", "bicycle", "car", "motorcycle", "airplane", "bus", "train", "truck", "boat",
    "traffic light", "fire hydrant", "stop sign", "parking meter", "bench", "bird", "cat", "dog",
    "horse", "sheep", "cow", "elephant", "bear", "zebra", "giraffe", "backpack", "umbrella",
    "handbag", "tie", "suitcase", "frisbee", "skis", "snowboard", "sports ball", "kite",
    "baseball bat", "baseball glove", "skateboard", "surfboard", "tennis racket", "bottle",
    "wine glass", "cup", "fork", "knife", "spoon", "bowl", "banana", "apple", "sandwich",
    "orange", "broccoli", "carrot", "hot dog", "pizza", "donut", "cake", "chair", "couch",
    "potted plant", "bed", "dining table", "toilet", "tv", "laptop", "mouse", "remote",
    "keyboard", "cell phone", "microwave", "oven", "toaster", "sink", "refrigerator", "book",
    "clock", "vase", "scissors", "teddy bear", "hair drier", "toothbrush")
"""COCO's 80 detection classes in the order YOLO-family models use."""


def read_labels(path: Path) -> tuple[str, ...]:
    """The class names of a label file, in order."""
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise VisionError(f"label file {path}: {exc.strerror or exc}") from exc
    except UnicodeDecodeError as exc:
        raise VisionError(f"label file {path}: not UTF-8 text ({exc.reason} at byte "
                          f"{exc.start})") from exc
    names = tuple(line.strip() for line in text.splitlines()
                  if line.strip() and not line.lstrip().startswith("#"))
    if not names:
        raise VisionError(f"label file {path} has no class names (one per line)")
    return names


def label_of(labels: tuple[str, ...], class_id: int) -> str:
    """The name of ``class_id``, or ``class_<id>`` when the label list is shorter."""
    return labels[class_id] if 0 <= class_id < len(labels) else f"class_{class_id}"
