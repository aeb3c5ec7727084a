"""Running a network: onnxruntime, or OpenCV's DNN module (ONNX files and Darknet cfg+weights).

A backend takes the ``1 x 3 x H x W`` input tensor and returns the network's output as one
array (OpenCV's Darknet importer gives one array per YOLO head; they are stacked).

* :class:`OnnxRuntimeBackend` — the fast default. ``threads`` sets onnxruntime's intra-op
  threads (0: one per core). With graph optimisation on (ENABLE_ALL), YOLOX-Nano at 416 runs in
  about 9 ms on two cores.
* :class:`OpenCvBackend` — ``cv2.dnn`` for ONNX files and, on OpenCV 4.x (OpenCV 5 removed the
  importer), Darknet ``.cfg`` + ``.weights``.
"""

from __future__ import annotations

import configparser
import re
from pathlib import Path
from typing import Protocol

import cv2
import numpy as np

from cyborg.vision.frames import VisionError


class Backend(Protocol):
    """What a detector asks of the runtime that runs its network."""

    name: str
    """The runtime, for messages: ``onnxruntime`` or ``opencv``."""
    input_hw: tuple[int, int]
    """``(height, width)`` in px of the network's input."""
    metadata: dict[str, str]
    """The model file's own metadata (an Ultralytics export's class names among them)."""

    def run(self, tensor: np.ndarray) -> np.ndarray:
        """The network's output for a ``1 x 3 x H x W`` float32 tensor, as one array."""
        ...


def _existing(path: Path, what: str) -> Path:
    if not path.is_file():
        problem = "is a folder" if path.is_dir() else "not found"
        raise VisionError(f"{what} {path}: {problem}")
    return path


def _static_hw(shape: list[object], model: Path, input_size: int | None) -> tuple[int, int]:
    height, width = shape[2], shape[3]
    if isinstance(height, int) and isinstance(width, int) and height > 0 and width > 0:
        if input_size is not None and (height, width) != (input_size, input_size):
            raise VisionError(f"model {model} takes {width}x{height} input, not the "
                              f"{input_size} asked for")
        return height, width
    if input_size is None:
        raise VisionError(f"model {model} has a dynamic input size {shape}; give one "
                          "(--input-size, e.g. 640)")
    return input_size, input_size


class OnnxRuntimeBackend:
    """An ONNX model on onnxruntime's CPU provider."""

    name = "onnxruntime"

    def __init__(self, model: Path, *, threads: int = 0, input_size: int | None = None) -> None:
        import onnxruntime as ort

        _existing(model, "model file")
        options = ort.SessionOptions()
        options.intra_op_num_threads = max(0, threads)
        options.inter_op_num_threads = 1
        options.graph_optimization_level = ort.GraphOptimizationLevel.ORT_ENABLE_ALL
        options.log_severity_level = 3
        try:
            self.session = ort.InferenceSession(str(model), options,
                                                providers=["CPUExecutionProvider"])
        except Exception as exc:  # onnxruntime raises its own exception types
            first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            raise VisionError(f"model file {model} cannot be loaded by onnxruntime: "
                              f"{first}") from exc
        inputs = self.session.get_inputs()
        if len(inputs) != 1 or len(inputs[0].shape) != 4:
            raise VisionError(f"model {model}: expected one image input 1 x 3 x H x W, found "
                              + ", ".join(f"{i.name} {i.shape}" for i in inputs))
        self.input_name = inputs[0].name
        self.input_hw = _static_hw(list(inputs[0].shape), model, input_size)
        self.output_names = [output.name for output in self.session.get_outputs()]
        self.output_shape = tuple(self.session.get_outputs()[0].shape)
        self.metadata = dict(self.session.get_modelmeta().custom_metadata_map)

    def run(self, tensor: np.ndarray) -> np.ndarray:
        """The model's first output for a ``1 x 3 x H x W`` float32 tensor."""
        output: np.ndarray = self.session.run(self.output_names[:1],
                                              {self.input_name: tensor})[0]
        return output


class OpenCvBackend:
    """A model on OpenCV's DNN module: an ONNX file, or Darknet ``cfg`` + ``weights``."""

    name = "opencv"

    def __init__(self, model: Path, *, weights: Path | None = None, threads: int = 0,
                 input_size: int | None = None) -> None:
        _existing(model, "model file")
        if threads > 0:
            cv2.setNumThreads(threads)
        self.metadata: dict[str, str] = {}
        if model.suffix == ".cfg":
            if weights is None:
                raise VisionError(f"Darknet model {model} needs its .weights file too")
            _existing(weights, "weights file")
            reader = getattr(cv2.dnn, "readNetFromDarknet", None)
            if reader is None:
                raise VisionError(
                    f"Darknet model {model}: OpenCV {cv2.__version__} cannot read Darknet "
                    "files (OpenCV 5 removed the importer). Install OpenCV 4 "
                    "(pip install 'opencv-python-headless<5') or convert the model to ONNX")
            try:
                self.net = reader(str(model), str(weights))
            except cv2.error as exc:
                raise VisionError(f"Darknet model {model}: {_first_line(exc)}") from exc
            self.input_hw = darknet_input_hw(model)
        else:
            try:
                self.net = cv2.dnn.readNet(str(model))
            except cv2.error as exc:
                raise VisionError(f"model file {model} cannot be loaded by OpenCV: "
                                  f"{_first_line(exc)}") from exc
            self.input_hw = _onnx_input_hw(model, input_size)
        self.output_layers = list(self.net.getUnconnectedOutLayersNames())

    def run(self, tensor: np.ndarray) -> np.ndarray:
        """The network's output for a ``1 x 3 x H x W`` tensor; several heads' rows stacked."""
        self.net.setInput(tensor)
        outputs = self.net.forward(self.output_layers)
        if len(outputs) == 1:
            return np.asarray(outputs[0])
        return np.concatenate([np.asarray(out).reshape(-1, out.shape[-1]) for out in outputs])


def darknet_input_hw(cfg: Path) -> tuple[int, int]:
    """``height, width`` from a Darknet cfg's ``[net]`` section."""
    parser = configparser.ConfigParser(strict=False, inline_comment_prefixes=("#", ";"))
    try:
        text = cfg.read_text(encoding="utf-8", errors="replace")
        first = re.search(r"^\s*\[net(work)?\]", text, re.MULTILINE)
        if first is None:
            raise VisionError(f"Darknet cfg {cfg}: no [net] section")
        end = re.search(r"^\s*\[", text[first.end():], re.MULTILINE)
        section = text[first.start(): first.end() + (end.start() if end else len(text))]
        parser.read_string(section.replace("[network]", "[net]"))
        return int(parser["net"]["height"]), int(parser["net"]["width"])
    except (KeyError, ValueError, configparser.Error) as exc:
        raise VisionError(f"Darknet cfg {cfg}: [net] needs integer width and height "
                          f"({exc})") from exc


def _onnx_input_hw(model: Path, input_size: int | None) -> tuple[int, int]:
    import onnxruntime as ort

    options = ort.SessionOptions()
    options.graph_optimization_level = ort.GraphOptimizationLevel.ORT_DISABLE_ALL
    try:
        session = ort.InferenceSession(str(model), options, providers=["CPUExecutionProvider"])
    except Exception as exc:
        raise VisionError(f"model file {model} is not a usable ONNX model: {exc}") from exc
    return _static_hw(list(session.get_inputs()[0].shape), model, input_size)


def _first_line(exc: Exception) -> str:
    lines = [line for line in str(exc).splitlines() if line.strip()]
    return lines[-1].strip() if lines else type(exc).__name__
