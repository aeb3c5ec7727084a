"""The run report: one self-contained HTML page of what a recording shows.

``cyborg report run.mcap -o run.html`` (wired by :mod:`cyborg.app.report_commands`) reads an
MCAP recording (:mod:`cyborg.record`'s, or any in the rosbag2 layout) and writes a page a user
opens in a browser, with no server: for each robot its tree with per-node status counts and
times, the path it drove on its map, its battery over time with the docked and charging
periods, the goals it reached and failed (what each path state means), the objects its
tracker followed and its detector's detections per minute, and its warnings; a header with the
run's metadata, its duration on the wall clock and in simulated time, and the messages per
topic. Every figure says which clock it is on.

* :mod:`cyborg.report.recording` — reading a file, complete or cut, and decoding the topics a
  report uses with the bus's message types;
* :mod:`cyborg.report.robots` — which robots (namespaces) a recording holds, and their topics;
* :mod:`cyborg.report.clocks` — the wall clock and simulated time (``/clock``) of a recording;
* :mod:`cyborg.report.tree_stats` — per-node counts, running time and tick time;
* :mod:`cyborg.report.goals` — goal attempts and their outcomes from the path state;
* :mod:`cyborg.report.battery` — the charge, and the charging and docked periods;
* :mod:`cyborg.report.detections` — tracked objects and detections per class per minute;
* :mod:`cyborg.report.warnings` — the log's warnings and what went wrong;
* :mod:`cyborg.report.svg`, :mod:`cyborg.report.map_svg` — charts and the map, as inline SVG;
* :mod:`cyborg.report.page`, :mod:`cyborg.report.sections` — the page and its sections;
* :mod:`cyborg.report.build` — all of it together: :func:`~cyborg.report.build.build_report`.

It builds on :mod:`cyborg.bus` (message types), :mod:`cyborg.interfaces` (topic names),
:mod:`cyborg.record` (the scan of a file, the metadata's names) and the engine's statuses and
structure outline (:mod:`cyborg.bt.status`, :mod:`cyborg.bt.outline`).

The package exports nothing itself: import the modules.
"""

__all__: list[str] = []
