"""The recorder as a component: its parameters, their defaults, and how it starts.

:func:`start` is the ``recorder`` kind of launch files (see :mod:`cyborg.bus.component`) and
what ``cyborg up --record`` runs: a :class:`~cyborg.record.recorder.Recorder` on node
:data:`~cyborg.record.recorder.NAME`, with these read-only bus parameters:

==================  ================================================================
parameter           meaning (default)
==================  ================================================================
``output``          the MCAP file to write (required); relative to the launch file
``topics``          topics to record ([]: all but hidden topics and images)
``exclude``         glob patterns of topics left out ([])
``images``          record image topics too, when recording all (false)
``compression``     ``none``, ``lz4`` or ``zstd`` (:func:`default_compression`)
``split_size``      start a new file past this size, e.g. ``1GiB`` ("": never)
``split_duration``  start a new file after this long, e.g. ``10m`` ("": never)
``map``, ``tree``   the map and tree files of the run, named in the metadata ("")
==================  ================================================================
"""

from __future__ import annotations

import shlex
import sys

from cyborg.bus import Context, Node
from cyborg.bus.component import NodeSpec
from cyborg.record.recorder import Recorder
from cyborg.record.selection import TopicSelection
from cyborg.record.split import RecordingFiles, SplitPolicy, parse_duration, parse_size

COMPRESSION = "zstd"
"""Compression of a recording without images unless told otherwise; docs/recording.md says
why."""
IMAGE_COMPRESSION = "none"
"""Compression of a recording that takes images unless told otherwise: zstd cannot keep up
with a camera's hundreds of MB a second on one core, lz4 takes about half a core and saves
little on pixels (docs/recording.md, "Compression")."""


def default_compression(images: bool) -> str:
    """The compression a recording uses unless one is named: none with images, else zstd."""
    return IMAGE_COMPRESSION if images else COMPRESSION


class RunningRecorder:
    """A started recorder."""

    def __init__(self, recorder: Recorder) -> None:
        self.recorder = recorder

    def describe(self) -> str:
        """Where the recording goes, and how to pause it."""
        pause = f"{self.recorder.node.fq_name}/pause"
        return (f"recorder     {self.recorder.files.paths[0]} (pause: cyborg service call "
                f"{pause} '{{data: true}}')")

    def stop(self) -> None:
        """Finishes the file and leaves the bus; says where the recording is."""
        self.recorder.close()
        stats, files = self.recorder.stats, self.recorder.files.paths
        where = ", ".join(str(path) for path in files)
        failure = f"; {self.recorder.failure}" if self.recorder.failure else ""
        dropped = f" ({stats.dropped} dropped)" if stats.dropped else ""
        print(f"recorded {stats.messages} messages{dropped} on {len(stats.topics)} topics into "
              f"{where}{failure}", file=sys.stderr, flush=True)


def start(context: Context, spec: NodeSpec) -> RunningRecorder:
    """Starts recording from ``spec``; a missing or existing output file refuses it."""
    node = Node(spec.name, spec.namespace, context=context, parameters=dict(spec.parameters))
    try:
        params = node.parameters
        output = str(params.declare("output", "", "the MCAP file to write", read_only=True))
        topics = params.declare("topics", [""], "topics to record (none: all)", read_only=True)
        exclude = params.declare("exclude", [""], "glob patterns of topics left out",
                                 read_only=True)
        images = bool(params.declare("images", False, "record images too", read_only=True))
        compression = str(params.declare(
            "compression", "", "none, lz4 or zstd (default: zstd; none with images)",
            read_only=True)) or default_compression(images)
        split_size = str(params.declare("split_size", "", "new file past this size",
                                        read_only=True))
        split_duration = str(params.declare("split_duration", "", "new file after this long",
                                            read_only=True))
        run = {key: str(params.declare(key, "", f"the run's {key} file", read_only=True))
               for key in ("map", "tree")}
        if not output:
            raise spec.error("output: name the MCAP file to write")
        try:
            selection = TopicSelection.of([str(t) for t in topics if t],
                                          [str(p) for p in exclude if p], images=images)
            policy = SplitPolicy(parse_size(split_size) if split_size else None,
                                 parse_duration(split_duration) if split_duration else None)
            files = RecordingFiles(spec.path(output), context.types, compression, policy)
        except (ValueError, FileExistsError) as exc:
            raise spec.error(str(exc)) from None
        run["command"] = shlex.join(["cyborg", *sys.argv[1:]])
        recorder = Recorder(node, files, selection,
                            run={key: value for key, value in run.items() if value})
    except BaseException:
        node.destroy()
        raise
    return RunningRecorder(recorder)


__all__ = ["COMPRESSION", "IMAGE_COMPRESSION", "RunningRecorder", "default_compression",
           "start"]
