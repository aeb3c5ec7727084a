"""Object detection on stereo images, with distance, and the detector node.

* camera sources behind one interface (:class:`FrameSource` of :class:`Frame`): images,
  folders, videos, stereo pairs, local cameras (:mod:`~cyborg.vision.file_sources`), ROS bags
  (:mod:`~cyborg.vision.bag_source`) and the bus (:mod:`~cyborg.vision.bus_source`), opened
  from a short description by :func:`open_source`;
* depth maps in metres from a depth camera or a rectified stereo pair
  (:mod:`~cyborg.vision.depth`);
* YOLO-family detectors (YOLOX, YOLOv5/v7, YOLOv8/11, YOLOv10, Darknet) on onnxruntime or
  OpenCV's DNN module (:class:`Detector`; :mod:`~cyborg.vision.layouts`,
  :mod:`~cyborg.vision.backends`, :mod:`~cyborg.vision.letterbox`);
* the distance of each detection: the median of valid depth in its box
  (:mod:`~cyborg.vision.distance`), the annotated image (:mod:`~cyborg.vision.annotate`), and
  the bus messages (:mod:`cyborg.interfaces.detection_messages`, shared with the simulated
  camera);
* the nodes: :class:`DetectorNode` and :class:`CameraNode`; model files by name or path
  (:func:`find_model`, :mod:`~cyborg.vision.models`), as ``cyborg detect --model`` finds
  them::

      from cyborg.vision import DetectionPipeline, Detector, open_source
      pipeline = DetectionPipeline(Detector.open("yolox_nano"))

This package uses the bus for its messages and nodes; only :mod:`cyborg.app` wires it up.
"""

from cyborg.vision.camera_node import CameraNode
from cyborg.vision.camera_topics import CameraTopics
from cyborg.vision.depth import StereoCalibration, StereoDepth, depth_in_metres
from cyborg.vision.detector import Detection, Detector
from cyborg.vision.detector_node import DetectorNode
from cyborg.vision.distance import box_distance
from cyborg.vision.frames import Frame, FrameSource, VisionError
from cyborg.vision.models import find_model
from cyborg.vision.pipeline import DetectionPipeline, Result
from cyborg.vision.sources import SourceOptions, open_source

__all__ = ["CameraNode", "CameraTopics", "Detection", "DetectionPipeline", "Detector",
           "DetectorNode", "Frame", "FrameSource", "Result", "SourceOptions", "StereoCalibration",
           "StereoDepth", "VisionError", "box_distance", "depth_in_metres", "find_model",
           "open_source"]
