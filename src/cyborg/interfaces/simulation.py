"""What only a simulator publishes: the true poses of the people walking in it.

Under the robot's namespace (``/cyborg`` by default; the first robot's, ``/robot1``, in a
fleet) the simulator publishes, while people walk on its map:

==================  ===========================  ============================================
topic               type                         content
==================  ===========================  ============================================
``sim/people``      geometry_msgs/PoseArray      every person's true pose in the ``map``
                                                 frame, heading where they walk; in the
                                                 people's fixed order (latched)
==================  ===========================  ============================================

It is ground truth for tests, benchmarks and displays, never a sensor: what the robot knows of
people comes from its laser and its camera's detections (:mod:`cyborg.interfaces.detector`).
"""

from __future__ import annotations

from cyborg.bus.msgs.geometry_msgs.msg import PoseArray
from cyborg.interfaces.contract import Topic

PEOPLE = Topic("sim/people", PoseArray, latched=True)
"""The simulated people's true poses (see the module doc)."""
TOPICS: tuple[Topic, ...] = (PEOPLE,)
"""Every topic of the contract."""
PERSON_LABEL = "person"
"""The class a person is detected as: COCO's, as the real detector names it."""
