"""Reading a mode file (TOML) into a checked :class:`~cyborg.modes.spec.MachineSpec`.

The file sits next to the editor project and names its trees::

    project = "mission.b3.json"        # or: files = ["patrol.json", "charge.json"]
    initial = "normal"
    min_dwell = 2.0                    # seconds; the default of every mode

    [modes.normal]
    tree = "Patrol"                    # a tree's id or title, or a file of `files`

    [modes.low_battery]
    tree = "Recharge"

    [[transitions]]
    from = "normal"
    to = "low_battery"
    when = "battery.percent < 20"

docs/modes.md describes every key; ``modes.schema.json`` beside this module is its JSON Schema.
:mod:`cyborg.modes.mode_reader` reads the parsed TOML into the spec.

Nothing half-loads: every problem is collected — TOML syntax, unknown or mistyped keys (with
the closest known key suggested), unknown trees (listing those there are), unknown modes in
``from``, ``to``, ``initial`` or ``then``, expressions that do not parse (with the column),
transitions without a trigger or with two, repeated transitions, modes no path reaches — and
:class:`ModeFileError` names them all, each with the file, the line and the mode or transition
(``transition 3 (normal → demo)``).

The file and its trees are one load within the caps of :mod:`cyborg.modes.caps`: one byte
budget for the mode file and every file it names, one node budget for all its modes' trees,
and at most so many modes and transitions.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

from cyborg.bt.files import FileRefusedError, read_text
from cyborg.bt.limits import Limits
from cyborg.bt.problems import Problem, TreeLoadError
from cyborg.modes import caps
from cyborg.modes.mode_reader import ModeFileReader
from cyborg.modes.spec import MachineSpec
from cyborg.modes.toml_bounds import MAX_DIGITS, MAX_NESTING, first_long_number, first_too_deep

_AT = re.compile(r"\(at line (\d+), column (\d+)\)")
_SURROGATE = re.compile("[\ud800-\udfff]")


class ModeFileError(TreeLoadError):
    """A mode file that cannot be used; :attr:`problems` lists every reason."""

    def __init__(self, problems: list[Problem]) -> None:
        super().__init__(problems)
        errors = [p for p in problems if p.is_error]
        count = f"{len(errors)} error{'s' if len(errors) != 1 else ''}"
        shown_errors = "\n".join(f"  {p}" for p in errors)
        self.args = (f"cannot load the mode file ({count}):\n{shown_errors}",)


def read_mode_file(path: str | Path, *, max_bytes: int | None = None,
                   max_depth: int | None = None, max_nodes: int | None = None) -> MachineSpec:
    """Reads, checks and resolves the mode file at ``path``; :class:`ModeFileError` if bad.

    ``max_bytes``, ``max_depth`` and ``max_nodes`` are the caps of the whole load (the mode
    file and its trees together, :mod:`cyborg.modes.caps`); left out, as for a tree file.
    """
    path = Path(path)
    source = str(path)
    limits = mode_file_limits(source, max_bytes, max_depth, max_nodes)
    try:
        text = read_text(path, limits)
    except FileRefusedError as exc:
        raise ModeFileError([Problem(exc.reason, source, exc.line)]) from None
    return parse_mode_file(text, source, path.parent, limits=limits)


def mode_file_limits(source: str, max_bytes: int | None = None, max_depth: int | None = None,
                     max_nodes: int | None = None) -> Limits:
    """The caps of one mode file's load (parameters, else the environment, else defaults)."""
    try:
        limits = Limits.resolve(max_bytes, max_depth, max_nodes, source=source)
    except TreeLoadError as exc:  # a bad CYBORG_TREE_MAX_* variable
        raise ModeFileError(exc.problems) from None
    limits.entry = "load_machine"
    return limits


def parse_mode_file(text: str, source: str = "<string>", folder: Path | None = None, *,
                    limits: Limits | None = None) -> MachineSpec:
    """Checks the mode file ``text``; tree files are found relative to ``folder``.

    ``limits`` are the load's caps, the text already counted (:func:`read_mode_file`'s); left
    out, new ones count the text.
    """
    if limits is None:
        limits = mode_file_limits(source)
        limits.bytes_read = len(text.encode("utf-8", "surrogatepass"))
    surrogate = _SURROGATE.search(text)
    if surrogate is not None:  # no file name or message could carry it
        line = text.count("\n", 0, surrogate.start()) + 1
        column = surrogate.start() - (text.rfind("\n", 0, surrogate.start()) + 1) + 1
        raise ModeFileError([Problem(
            f"the text holds a lone UTF-16 surrogate (U+{ord(surrogate.group()):04X}), which "
            "is not a character", source, line, column)])
    _check_bounds(text, source)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        message = str(exc)
        at = _AT.search(message)
        where = (int(at.group(1)), int(at.group(2))) if at else (
            max(1, len(text.splitlines())), None)
        reason = _AT.sub("", message).replace("(at end of document)", "at the end").strip()
        raise ModeFileError([Problem(f"not valid TOML: {reason}", source, *where)]) from None
    reader = ModeFileReader(text, source, folder if folder is not None else Path.cwd(), limits)
    spec = reader.read(data)
    if reader.problems or spec is None:
        raise ModeFileError(reader.listed())
    return spec


def _check_bounds(text: str, source: str) -> None:
    """Refuses, located, what :mod:`tomllib` cannot read safely (:mod:`.toml_bounds`)."""
    long_text = caps.first_past_text_cap(text)
    if long_text is not None:
        raise ModeFileError([Problem(
            f"the mode file holds more than {caps.MAX_TEXT_BYTES:,} bytes, more than a mode "
            "file may (cyborg.modes.caps.MAX_TEXT_BYTES)", source, long_text)])
    deep = first_too_deep(text)
    if deep is not None:
        raise ModeFileError([Problem(
            f"arrays and inline tables nested more than {MAX_NESTING} deep (a mode file needs "
            "two or three levels)", source, *deep)])
    long = first_long_number(text)
    if long is not None:
        raise ModeFileError([Problem(
            f"a number of more than {MAX_DIGITS} digits (no setting needs more than 20)",
            source, *long)])
