"""Reading a mode file's parsed TOML into a :class:`~cyborg.modes.spec.MachineSpec`.

:func:`cyborg.modes.mode_file.parse_mode_file` checks the text and parses it with ``tomllib``;
:class:`ModeFileReader` then reads the tables: the files named (:mod:`cyborg.modes.tree_sources`),
each mode and its tree, each transition and its conditions, and checks that every mode can be
reached. Every problem is collected with its line (:mod:`cyborg.modes.toml_lines`), up to
:data:`cyborg.modes.caps.MAX_PROBLEMS`; a file past the caps of :mod:`cyborg.modes.caps` is
refused before its modes are read.
"""

from __future__ import annotations

import difflib
import math
import re
from pathlib import Path
from typing import Any

from cyborg.bt.limits import Limits
from cyborg.bt.problems import Problem, printable, shown
from cyborg.modes import caps
from cyborg.modes.conditions import Condition, ExpressionError
from cyborg.modes.spec import ANY, MachineSpec, ModeSpec, TransitionSpec, reachable
from cyborg.modes.toml_lines import TomlLines
from cyborg.modes.tree_sources import TreeSource, find_tree, read_sources

TOP_KEYS = ("project", "files", "initial", "min_dwell", "description", "modes", "transitions")
MODE_KEYS = ("tree", "min_dwell", "max_time", "then", "description")
TRANSITION_KEYS = ("from", "to", "when", "event", "on_request", "guard", "reason")
NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_-]*\Z")
"""Mode and event names: they appear on the command line and in the monitor."""
_COLUMN = re.compile(r"at column (\d+)")



class ModeFileReader:
    """Reads the parsed TOML of one mode file into a spec, collecting every problem."""

    def __init__(self, text: str, source: str, folder: Path, limits: Limits) -> None:
        self.source = source
        self.folder = folder
        self.limits = limits
        self.lines = TomlLines(text)
        self.text_lines = text.splitlines()
        self.problems: list[Problem] = []
        self.unlisted: list[int] = []
        """The lines of the problems past :data:`caps.MAX_PROBLEMS`, which are not listed."""

    @property
    def full(self) -> bool:
        """Whether no more problems are listed (:data:`caps.MAX_PROBLEMS`)."""
        return len(self.problems) >= caps.MAX_PROBLEMS

    def problem(self, message: str, *path: str | int, field: str | None = None,
                column: int | None = None) -> None:
        """Adds a problem at the line of ``path`` (or the nearest table above it)."""
        line = self.lines.line(*path) or 1  # a key missing from the file: its top
        if self.full:
            self.unlisted.append(line)
            return
        self.problems.append(Problem(printable(message), self.source, line, column,
                                     field=field))

    def listed(self) -> list[Problem]:
        """The problems, and one more line for those past :data:`caps.MAX_PROBLEMS`."""
        if not self.unlisted:
            return self.problems
        count = len(self.unlisted)
        return [*self.problems, Problem(
            f"and {count:,} more problem{'s' if count != 1 else ''} from this line on, not "
            f"listed (a mode file's first {caps.MAX_PROBLEMS} are)", self.source,
            self.unlisted[0])]

    # ------------------------------------------------------------------ the whole file
    def read(self, data: dict[str, Any]) -> MachineSpec | None:
        """The spec of the whole file, or None when it has problems (in :attr:`problems`)."""
        self.unknown_keys(data, TOP_KEYS, "the file", ())
        sources = self.sources(data)
        default_dwell = self.seconds(data, "min_dwell", "the file", (), default=0.0,
                                     zero=True) or 0.0
        raw_modes = data.get("modes")
        if not isinstance(raw_modes, dict) or not raw_modes:
            self.problem("the file declares no mode: add a table such as [modes.normal] with "
                         "tree = \"...\"", "modes", field="modes")
            raw_modes = {}
        raw_transitions = data.get("transitions", [])
        if self.too_many(raw_modes, raw_transitions):
            return None
        names = list(raw_modes)
        modes: dict[str, ModeSpec] = {}
        for name, raw in raw_modes.items():
            mode = self.mode(name, raw, names, sources, default_dwell)
            if mode is not None:
                modes[name] = mode
        initial = data.get("initial")
        if not isinstance(initial, str):
            self.problem("'initial' must name the mode the machine starts in"
                         + (f", one of {_quoted(names)}" if names else ""), "initial",
                         field="initial")
            initial = None
        elif initial not in raw_modes:
            self.problem(f"'initial' names the mode {initial!r}, which is not declared"
                         f"{_suggest(initial, names)}", "initial", field="initial")
            initial = None
        transitions = self.transitions(raw_transitions, names)
        whole = len(modes) == len(raw_modes) and isinstance(raw_transitions, list) \
            and len(transitions) == len(raw_transitions)
        if initial is not None and whole:  # else a broken transition may be the missing path
            for name in sorted(set(modes) - reachable(initial, modes, transitions)):
                self.problem(f"mode {name!r} cannot be reached from the initial mode "
                             f"{initial!r}: no transition or 'then' leads to it", "modes", name)
        if self.problems or self.unlisted or initial is None:
            return None
        self.problems.extend(caps.node_budget(modes.values(), self.limits, self.source))
        return MachineSpec(self.source, modes, initial, transitions, default_dwell)

    def too_many(self, modes: dict[str, Any], transitions: Any) -> bool:
        """Whether the file declares more modes or transitions than a mode file may."""
        before = len(self.problems)
        if len(modes) > caps.MAX_MODES:
            past = list(modes)[caps.MAX_MODES]
            self.problem(caps.too_many("modes", len(modes), caps.MAX_MODES,
                                       f"mode {past!r}"), "modes", past, field="modes")
        if isinstance(transitions, list) and len(transitions) > caps.MAX_TRANSITIONS:
            self.problem(caps.too_many("transitions", len(transitions), caps.MAX_TRANSITIONS,
                                       f"transition {caps.MAX_TRANSITIONS + 1}"),
                         "transitions", caps.MAX_TRANSITIONS, field="transitions")
        return len(self.problems) > before

    def sources(self, data: dict[str, Any]) -> list[TreeSource]:
        """Reads the files ``project`` or ``files`` name, within the load's caps."""
        project, files = data.get("project"), data.get("files")
        if project is not None and files is not None:
            self.problem("give either 'project' (one editor file) or 'files' (a list), not "
                         "both", "files", field="files")
            return []
        if project is None and files is None:
            self.problem("the file names no trees: add project = \"<editor project>.json\" "
                         "or files = [\"<tree>.json\", ...]", field="project")
            return []
        key = "project" if project is not None else "files"
        written = [project] if project is not None else files
        if not isinstance(written, list) or not written or not all(
                isinstance(item, str) and item and "\0" not in item for item in written):
            wanted = "a file name" if key == "project" else "a list of file names"
            self.problem(f"{key!r} must be {wanted}, not {shown(data[key])}", key, field=key)
            return []
        for index, name in enumerate(written):
            if name in written[:index]:
                self.problem(f"{key!r} names {name!r} twice", key, field=key)
        sources, failed = read_sources(self.folder, list(dict.fromkeys(written)), self.limits)
        for name, problems in failed.items():
            self.problem(f"{key!r} names {name!r}, which does not load (its problems follow)",
                         key, field=key)
            self.problems.extend(problems)
        return sources

    # ------------------------------------------------------------------ modes
    def mode(self, name: str, raw: Any, names: list[str], sources: list[TreeSource],
             default_dwell: float) -> ModeSpec | None:
        """One mode's spec, its tree found in ``sources``; None when it has problems."""
        where = f"mode {name!r}"
        before = len(self.problems)
        if name == ANY or not NAME.match(name):
            self.problem(f"{where}: a mode's name is a letter or '_' followed by letters, "
                         "digits, '_' or '-'", "modes", name)
        if not isinstance(raw, dict):
            self.problem(f"{where} must be a table with at least tree = \"...\", not "
                         f"{shown(raw)}", "modes", name)
            return None
        self.unknown_keys(raw, MODE_KEYS, where, ("modes", name))
        tree = raw.get("tree")
        found: Any = None
        if not isinstance(tree, str) or not tree:
            self.problem(f"{where}: 'tree' must name the tree the mode runs (its id or title"
                         ", or a file of 'files')", "modes", name, "tree", field="tree")
        elif sources:
            found = find_tree(sources, tree)
            if isinstance(found, str):
                self.problem(f"{where}: {found}", "modes", name, "tree", field="tree")
        dwell = self.seconds(raw, "min_dwell", where, ("modes", name), default=default_dwell,
                             zero=True)
        max_time = self.seconds(raw, "max_time", where, ("modes", name), default=None)
        then = raw.get("then")
        if then is not None and (not isinstance(then, str) or then not in names):
            self.problem(f"{where}: 'then' names the mode {shown(then)}, which is not "
                         f"declared{_suggest(then, names)}", "modes", name, "then",
                         field="then")
        elif (then is None) != (raw.get("max_time") is None):
            missing = "then" if then is None else "max_time"
            self.problem(f"{where}: 'max_time' and 'then' go together (after max_time seconds "
                         f"the mode is left for then); '{missing}' is missing", "modes", name,
                         field=missing)
        elif then == name:
            self.problem(f"{where}: 'then' leads back to the mode itself", "modes", name,
                         "then", field="then")
        description = raw.get("description", "")
        if not isinstance(description, str):
            self.problem(f"{where}: 'description' must be text", "modes", name, "description")
        if len(self.problems) > before or not isinstance(found, tuple):
            return None
        return ModeSpec(name, found[1], found[0], dwell or 0.0, max_time, then,
                        description, self.lines.line("modes", name))

    # ------------------------------------------------------------------ transitions
    def transitions(self, raw: Any, names: list[str]) -> tuple[TransitionSpec, ...]:
        """The transitions in file order, each checked; a repeated one is a problem."""
        if not isinstance(raw, list):
            self.problem("'transitions' must be an array of tables ([[transitions]])",
                         "transitions", field="transitions")
            return ()
        found: list[TransitionSpec] = []
        seen: dict[tuple[Any, ...], int] = {}
        for index, item in enumerate(raw):
            transition = self.transition(index, item, names)
            if transition is None:
                continue
            key = (transition.sources, transition.target, transition.trigger,
                   transition.guard.source if transition.guard else None)
            if key in seen:
                self.problem(f"{transition.label} repeats transition {seen[key]}",
                             "transitions", index)
                continue
            seen[key] = transition.number
            found.append(transition)
        return tuple(found)

    def transition(self, index: int, raw: Any, names: list[str]) -> TransitionSpec | None:
        """The transition at ``index``; None when it has problems."""
        number = index + 1
        path = ("transitions", index)
        if not isinstance(raw, dict):
            self.problem(f"transition {number} must be a table, not {shown(raw)}", *path)
            return None
        sources_raw, target = raw.get("from"), raw.get("to")
        sources = ([sources_raw] if isinstance(sources_raw, str) else sources_raw
                   if isinstance(sources_raw, list) else [])
        where = (f"transition {number} ({', '.join(map(str, sources)) or '?'} → "
                 f"{target if isinstance(target, str) else '?'})")
        before = len(self.problems)
        self.unknown_keys(raw, TRANSITION_KEYS, where, path)
        if not sources or not all(isinstance(s, str) for s in sources):
            self.problem(f"{where}: 'from' must name a mode, a list of modes, or \"*\" for "
                         "any mode", *path, "from", field="from")
        elif ANY in sources and len(sources) > 1:
            self.problem(f"{where}: '*' already means every mode; list no others beside it",
                         *path, "from", field="from")
        else:
            for mode in sources:
                if mode != ANY and mode not in names:
                    self.problem(f"{where}: 'from' names the mode {mode!r}, which is not "
                                 f"declared{_suggest(mode, names)}", *path, "from",
                                 field="from")
        if not isinstance(target, str):
            self.problem(f"{where} leads nowhere: 'to' must name the mode it enters"
                         + (f", one of {_quoted(names)}" if names else ""), *path,
                         field="to")
        elif target not in names:
            self.problem(f"{where} leads nowhere: 'to' names the mode {target!r}, which is "
                         f"not declared{_suggest(target, names)}", *path, "to", field="to")
        elif target in sources:
            self.problem(f"{where} leads back to the mode it leaves", *path, "to", field="to")
        when = self.condition(raw, "when", where, path)
        guard = self.condition(raw, "guard", where, path)
        event = raw.get("event")
        if event is not None and (not isinstance(event, str) or not NAME.match(event)):
            self.problem(f"{where}: 'event' is a name (a letter or '_' followed by letters, "
                         f"digits, '_' or '-'), not {shown(event)}", *path, "event",
                         field="event")
        on_request = raw.get("on_request", False)
        if not isinstance(on_request, bool):
            self.problem(f"{where}: 'on_request' must be true or false, not "
                         f"{shown(on_request)}", *path, "on_request", field="on_request")
            on_request = False
        triggers = [key for key in ("when", "event") if key in raw] + (
            ["on_request"] if on_request else [])
        if len(triggers) != 1:
            what = ("has no trigger" if not triggers
                    else f"has {len(triggers)} triggers ({', '.join(triggers)})")
            self.problem(f"{where} {what}: give exactly one of when = \"<condition>\", "
                         "event = \"<name>\" or on_request = true", *path)
        reason = raw.get("reason", "")
        if not isinstance(reason, str):
            self.problem(f"{where}: 'reason' must be text", *path, "reason", field="reason")
        if len(self.problems) > before:
            return None
        return TransitionSpec(number, tuple(sources), str(target), when, event, on_request,
                              guard, str(reason), self.lines.line(*path))

    def condition(self, raw: dict[str, Any], key: str, where: str,
                  path: tuple[str | int, ...]) -> Condition | None:
        """The condition under ``key`` (``when``, ``guard``), parsed; None if absent or bad."""
        text = raw.get(key)
        if text is None:
            return None
        if not isinstance(text, str):
            self.problem(f"{where}: {key!r} must be a condition in text, such as "
                         f"\"battery.percent < 20\", not {shown(text)}", *path, key, field=key)
            return None
        try:
            return Condition(text)
        except ExpressionError as exc:
            self.problem(f"{where}: {key!r} does not parse: {exc}", *path, key, field=key,
                         column=self.column(exc, text, (*path, key)))
            return None

    def column(self, error: ExpressionError, text: str, path: tuple[str | int, ...]) -> int | None:
        """The error's column in the file, when the expression is written there as it is."""
        at = _COLUMN.search(str(error))
        line = self.lines.line(*path)
        if at is None or line is None or not text:
            return None
        start = self.text_lines[line - 1].find(text)
        return start + int(at.group(1)) if start >= 0 else None

    # ------------------------------------------------------------------ values
    def seconds(self, raw: dict[str, Any], key: str, where: str, path: tuple[str | int, ...],
                *, default: float | None, zero: bool = False) -> float | None:
        """A number of seconds under ``key``: finite, above 0 (or 0 with ``zero``)."""
        value = raw.get(key)
        if value is None:
            return default
        if type(value) not in (int, float) or not math.isfinite(value) \
                or value < 0 or (value == 0 and not zero):
            least = "0 or more" if zero else "more than 0"
            self.problem(f"{where}: {key!r} is a number of seconds, {least}, not "
                         f"{shown(value)}", *path, key, field=key)
            return default
        return float(value)

    def unknown_keys(self, raw: dict[str, Any], known: tuple[str, ...], where: str,
                     path: tuple[str | int, ...]) -> None:
        """A problem for each key of ``raw`` not in ``known``, with the closest suggested."""
        for key in raw:
            if key not in known and self.full:
                self.problem("", *path, key)  # counted only: no close match looked for
            elif key not in known:
                self.problem(f"{where}: unknown key {key!r}{_close(key, list(known))}; "
                             f"known keys: {', '.join(known)}", *path, key, field=key)


def _close(word: Any, choices: list[str]) -> str:
    """`` (did you mean 'tree'?)`` when one of ``choices`` is close to ``word``."""
    if not isinstance(word, str):
        return ""
    close = difflib.get_close_matches(word, choices, n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def _suggest(word: Any, modes: list[str]) -> str:
    """The close mode name if there is one, else the list of the modes declared."""
    return _close(word, modes) or (f"; modes: {_quoted(modes)}" if modes else "")


def _quoted(names: list[str]) -> str:
    return ", ".join(repr(name) for name in names)
