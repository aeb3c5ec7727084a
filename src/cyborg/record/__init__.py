"""Recording the bus into MCAP files that ``ros2 bag``, Foxglove and rosbags read.

* :mod:`cyborg.record.layout` — the rosbag2 layout of an MCAP file: profile, encodings,
  ``ros2msg`` schema text, the channel metadata (QoS profiles, type hash);
* :mod:`cyborg.record.selection` — which topics a recording takes (names, excludes, images);
* :mod:`cyborg.record.guarded_stream` — the file under a recording: writes whole records or
  fails cleanly, remembering where the last whole one ended;
* :mod:`cyborg.record.mcap_file` — one MCAP file being written, flushed at a bounded interval;
* :mod:`cyborg.record.split` — a recording's files: one, or a series split by size or duration;
* :mod:`cyborg.record.scan` and :mod:`cyborg.record.completion` — reading a file record by
  record up to where it was cut, and writing the indexes and summary it lacks;
* :mod:`cyborg.record.recover` — ``cyborg record --recover``: a readable, indexed copy of a
  cut file;
* :mod:`cyborg.record.recorder` — the recorder on the bus: finds topics in the graph,
  subscribes to their raw CDR, writes, pauses and resumes;
* :mod:`cyborg.record.component` — the recorder as a component (``cyborg up --record``);
* :mod:`cyborg.record.recorded` — what every recording to play tells: its topics, time span,
  whether it was cut, and its messages in time order as CDR;
* :mod:`cyborg.record.mcap_recording` and :mod:`cyborg.record.bag_recording` — reading MCAP
  files (whole or cut) and ROS 1 and ROS 2 bags; :mod:`cyborg.record.playback_source` opens
  the right one (``open_recording``);
* :mod:`cyborg.record.player` — the player on the bus (``cyborg play``): timing, ``/clock``,
  latches, pause, step, seek and its state.

This package builds on :mod:`cyborg.bus` and :mod:`cyborg.interfaces` only; the command line
(:mod:`cyborg.app`) wires it. docs/recording.md says what a recording holds.

The package exports nothing itself: import the modules.
"""

__all__: list[str] = []
