"""Navigation on ARNL maps: maps, poses and paths, occupancy grids, the planner, its services.

* :mod:`~cyborg.nav.arnl_map` reads ``.map`` files, with :mod:`~cyborg.nav.map_syntax` (the
  small print of a line), :mod:`~cyborg.nav.map_objects` (what goals, docks and forbidden zones
  mean) and :mod:`~cyborg.nav.map_limits` (caps on what a map may cost);
* :mod:`~cyborg.nav.geometry`: poses and paths in the map frame (metres, radians), to and from
  ROS messages;
* :mod:`~cyborg.nav.grid` rasterises a map; :mod:`~cyborg.nav.footprint` is the robot's shape;
* :mod:`~cyborg.nav.planner` plans paths on the grid (its kernels: :mod:`~cyborg.nav.search`);
* :mod:`~cyborg.nav.services` serves maps and plans on the bus.

The package exports nothing itself: import the modules.
"""

__all__: list[str] = []
