"""The 2018 approach in the detector benchmark, as the 2018 Python ROS 1 node did it.

* inference: OpenCV DNN (``cv2.dnn.readNet`` on the same ONNX file: the 2018 Darknet YOLOv3
  weights are not available, and OpenCV 5 removed the Darknet importer);
* ``cv2.dnn.blobFromImage`` stretch-resize without letterbox;
* the 2018 per-row Python loop over the output with no non-maximum suppression (every row above
  the threshold kept); YOLOX's raw head is first turned into what OpenCV's Darknet Region layer
  handed the 2018 node (:func:`region_output`);
* distance as the mean depth over the whole box; drawing as the 2018 node drew, with OpenCV's
  ``rectangle`` and ``putText`` on a copy of the frame (:func:`draw_2018`);
* transport: the frame is sent to the detector's process as a pickled ``multiprocessing`` Pipe
  ``send((stamp, image, depth))``, standing in for the 2018 node's serialised ROS 1 transport.
"""

from __future__ import annotations

import contextlib
import dataclasses
import multiprocessing
import threading
import time
import warnings
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from benchmarks.detector_frames import THRESHOLD, Frames, Offer, Run, offer_frames, stages_of
from cyborg.vision.annotate import BOX_COLOUR, FONT, caption
from cyborg.vision.detector import Detection
from cyborg.vision.distance import box_mean_2018
from cyborg.vision.labels import COCO
from cyborg.vision.layouts import yolox_grid


def draw_2018(image: np.ndarray, detections: list[Detection]) -> np.ndarray:
    """A copy of the frame with each box and caption drawn by OpenCV, one call after another."""
    drawn = image.copy()
    for detection in detections:
        x1, y1, x2, y2 = (round(value) for value in detection.box)
        cv2.rectangle(drawn, (x1, y1), (x2, y2), BOX_COLOUR, 2)
        cv2.putText(drawn, caption(detection), (x1, max(y1 - 5, 15)), FONT, 1.0, (0, 0, 0), 2)
    return drawn


def region_output(raw: np.ndarray, grid: tuple[np.ndarray, np.ndarray],
                  input_hw: tuple[int, int]) -> np.ndarray:
    """YOLOX's raw head as OpenCV's Darknet Region layer handed it to the 2018 node.

    Normalised centre x, y, w, h, objectness, then class columns = objectness x class score,
    zeroed below the threshold (the Region layer did this inside ``forward``, in C++).
    """
    rows = raw.reshape(-1, raw.shape[-1])
    cells, strides = grid
    size = np.array([input_hw[1], input_hw[0]], dtype=np.float32)
    out = np.empty_like(rows)
    out[:, :2] = (rows[:, :2] + cells) * strides / size
    out[:, 2:4] = np.exp(rows[:, 2:4]) * strides / size
    out[:, 4] = rows[:, 4]
    classes = rows[:, 5:] * rows[:, 4:5]
    classes[classes < THRESHOLD] = 0
    out[:, 5:] = classes
    return out


def detect_2018(rows: np.ndarray, width: int, height: int) -> list[Detection]:
    """The 2018 node's post-processing: a Python loop over every row, no NMS."""
    detections = []
    for row in rows:
        scores = row[5:]
        class_id = int(np.argmax(scores))
        confidence = float(scores[class_id])
        if confidence > THRESHOLD:
            centre_x, centre_y = int(row[0] * width), int(row[1] * height)
            box_w, box_h = int(row[2] * width), int(row[3] * height)
            left, top = int(centre_x - box_w / 2), int(centre_y - box_h / 2)
            detections.append(Detection(COCO[class_id], class_id, confidence,
                                        (left, top, left + box_w, top + box_h)))
    return detections


def peer_2018(frames_in: Connection, answers: Connection, model: str, threads: int) -> None:
    """The 2018 detector process: frames from the Pipe in, predictions out."""
    warnings.simplefilter("ignore", RuntimeWarning)  # nanmean of an empty or all-NaN box
    cv2.setNumThreads(threads)
    net = cv2.dnn.readNet(model)
    outputs = list(net.getUnconnectedOutLayersNames())
    input_hw = (416, 416)
    grid = yolox_grid(input_hw)
    records: list[dict[str, float]] = []
    while True:
        item = frames_in.recv()
        if item is None:
            return
        if item == "report":
            answers.send(records)
            records = []
            continue
        if item[0] == "bare":
            blob = cv2.dnn.blobFromImage(item[2], 1.0, input_hw, (0, 0, 0), swapRB=False)
            bare = []
            for _ in range(item[1]):
                started = time.perf_counter()
                net.setInput(blob)
                net.forward(outputs)
                bare.append((time.perf_counter() - started) * 1e3)
            answers.send(bare)
            continue
        stamp, image, depth = item
        arrived = time.time_ns()
        t0 = time.perf_counter()
        # YOLOX wants BGR 0..255; the 2018 node gave its Darknet model 1/255 and the default order
        blob = cv2.dnn.blobFromImage(image, 1.0, input_hw, (0, 0, 0), swapRB=False, crop=False)
        t1 = time.perf_counter()
        net.setInput(blob)
        raw = np.asarray(net.forward(outputs)[0])
        t2 = time.perf_counter()
        detections = detect_2018(region_output(raw, grid, input_hw), image.shape[1],
                                 image.shape[0])
        t3 = time.perf_counter()
        detections = [dataclasses.replace(found, distance=box_mean_2018(depth, found.box))
                      for found in detections]
        t4 = time.perf_counter()
        draw_2018(image, detections)
        t5 = time.perf_counter()
        answers.send((stamp, [{"label": found.label, "confidence": found.confidence,
                               "distance": found.distance, "polygon": found.corners}
                              for found in detections]))
        t6 = time.perf_counter()
        records.append({"transport": (arrived - stamp) / 1e6, "preprocess": (t1 - t0) * 1e3,
                        "inference": (t2 - t1) * 1e3, "postprocess": (t3 - t2) * 1e3,
                        "distance": (t4 - t3) * 1e3, "drawing": (t5 - t4) * 1e3,
                        "publish": (t6 - t5) * 1e3, "detections": float(len(detections))})


class Approach2018:
    """A camera here sending pickled frames down a Pipe to the 2018 detector's process."""

    def __init__(self, frames: Frames, model: Path, threads: int) -> None:
        self.frames = frames
        spawn = multiprocessing.get_context("spawn")
        frames_in, self.frames_out = spawn.Pipe(duplex=False)
        self.answers, answers_out = spawn.Pipe(duplex=False)
        self.peer = spawn.Process(target=peer_2018, daemon=True,
                                  args=(frames_in, answers_out, str(model), threads))
        self.peer.start()
        self.offer = Offer(1)
        self.replies: list[Any] = []
        self.replied = threading.Condition()
        threading.Thread(target=self._listen, daemon=True).start()

    def _listen(self) -> None:
        while True:
            try:
                answer = self.answers.recv()
            except EOFError:
                return
            if isinstance(answer, tuple):
                self.offer.answer(answer[0])
                continue
            with self.replied:
                self.replies.append(answer)
                self.replied.notify()

    def _ask(self, request: Any) -> Any:
        self.frames_out.send(request)
        with self.replied:
            if not self.replied.wait_for(lambda: bool(self.replies), timeout=120):
                raise RuntimeError("the 2018 detector process does not answer")
            return self.replies.pop()

    def _send(self, stamp: int, index: int) -> None:
        image, depth = self.frames[index % len(self.frames)]
        self.frames_out.send((stamp, image, depth))

    def bare(self, count: int) -> Run:
        """OpenCV DNN's ``forward`` alone on a prepared blob, in the detector's process."""
        return Run.inference_alone(self._ask(("bare", count, self.frames[0][0])))

    def run(self, count: int, window: int) -> Run:
        self._ask("report")
        self.offer = Offer(window)
        run = offer_frames(self._send, self.offer, count)
        return stages_of(self._ask("report"), run)

    def close(self) -> None:
        with contextlib.suppress(OSError):  # the process may be gone already
            self.frames_out.send(None)
        self.peer.join(10)
