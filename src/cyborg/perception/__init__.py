"""Objects on the map: the detector's predictions placed on the map and tracked over frames.

* :mod:`~cyborg.perception.screening` — which predictions can be placed, the rest counted by
  reason (NaN or negative distances, boxes outside the image, unknown labels, floods);
* :mod:`~cyborg.perception.sighting` — a detection's world position: robot pose + camera mount
  + bearing from the box centre + distance;
* :mod:`~cyborg.perception.tracker` — sightings of one label near one place become one object
  with an id, a velocity, a last-seen time and a confidence; forgotten after a timeout;
  :func:`~cyborg.perception.tracker.track_frames` runs it over recorded or simulated frames;
* :mod:`~cyborg.perception.objects_message` — the objects as the ``objects`` topic carries them;
* :mod:`~cyborg.perception.node` and :mod:`~cyborg.perception.component` — the tracker on the
  bus (the ``tracker`` kind, started by ``cyborg up``).

The core (screening, sighting, tracker) is plain Python and numpy with no I/O and no clock; the
node puts it on the bus. This package builds on :mod:`cyborg.interfaces` (the contracts of the
detector, the robot and the objects) and :mod:`cyborg.bus` only; see docs/perception.md.
"""

from cyborg.perception.screening import Rejections, screen
from cyborg.perception.sighting import Detection, RobotPose, Sighting, locate
from cyborg.perception.tracker import TrackedObject, Tracker, TrackerSettings, track_frames

__all__ = ["Detection", "Rejections", "RobotPose", "Sighting", "TrackedObject", "Tracker",
           "TrackerSettings", "locate", "screen", "track_frames"]
