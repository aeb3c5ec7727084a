"""``Say{text}``: the robot speaks a sentence, which may name what the blackboard holds.

The node publishes its text on the robot's ``say`` topic (:mod:`cyborg.interfaces.perception`)
for a speech node to say, and succeeds at once (it does not wait for the speech).

**Placeholders.** ``{name}`` in the text is replaced by the blackboard entry ``name`` when the
node runs; ``{name.field}`` takes a field of an entry that is a mapping (what ``ClosestObject``
writes: ``Hello {closest.label}, you are {closest.distance:.1f} m away!``); after a colon comes
a Python format specification (``.1f``: one decimal). ``{{`` and ``}}`` write braces. A text
that cannot be a template — an unclosed ``{``, an empty ``{}``, a number ``{0}``, a conversion
``{name!r}``, or a name with a space or bracket — is refused when the tree loads, naming the
node. An entry missing when the node runs, or a value the specification does not fit, fails the
node (FAILURE, the reason in ``reason``) and says nothing.
"""

from __future__ import annotations

import re
import string
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from typing_extensions import override

from cyborg.bt import FAILURE, SUCCESS, Action, Status, register
from cyborg.robot.perceiving import perceiving_robot_of
from cyborg.robot.protocol import ROBOT

_NAME = re.compile(r"[A-Za-z_][\w-]*(\.[A-Za-z_][\w-]*)*")
"""A placeholder's name: a blackboard key, then fields of mappings, separated by dots."""


@dataclass(frozen=True)
class Template:
    """A checked text with placeholders (see the module docstring)."""

    parts: tuple[tuple[str, str | None, str], ...]
    """``(literal text, placeholder name or None, format specification)`` in order."""

    @classmethod
    def parse(cls, text: str) -> Template:
        """The template of ``text``; ValueError saying what is wrong with it."""
        try:
            pieces = list(string.Formatter().parse(text))
        except ValueError as exc:
            raise ValueError(f"text {text!r} is not a template: {exc} (write {{{{ and }}}} "
                             "for braces)") from exc
        parts: list[tuple[str, str | None, str]] = []
        for literal, name, spec, conversion in pieces:
            if name is None:
                parts.append((literal, None, ""))
                continue
            if conversion:
                raise ValueError(f"text {text!r}: {{{name}!{conversion}}} — conversions are "
                                 "not supported; write {name} or {name:spec}")
            if not _NAME.fullmatch(name):
                raise ValueError(f"text {text!r}: {{{name}}} does not name a blackboard entry "
                                 "(write {key} or {key.field})")
            if spec and "{" in spec:
                raise ValueError(f"text {text!r}: nested placeholders in {{{name}:{spec}}}")
            parts.append((literal, name, spec or ""))
        return cls(tuple(parts))

    def render(self, values: Mapping[str, Any]) -> str:
        """The text with each placeholder filled from ``values``.

        KeyError (a missing entry or field) or ValueError (a value the specification does not
        fit) names the placeholder that cannot be filled.
        """
        out: list[str] = []
        for literal, name, spec in self.parts:
            out.append(literal)
            if name is None:
                continue
            key, *fields = name.split(".")
            if key not in values:
                raise KeyError(f"the blackboard has no {key!r} (for {{{name}}})")
            value = values[key]
            for depth, item in enumerate(fields):
                if not isinstance(value, Mapping) or item not in value:
                    where = ".".join([key, *fields[:depth]])
                    raise KeyError(f"{where} has no field {item!r} (for {{{name}}})")
                value = value[item]
            try:
                out.append(format(value, spec))
            except (TypeError, ValueError) as exc:
                raise ValueError(f"{{{name}:{spec}}} does not fit {value!r}: {exc}") from exc
        return "".join(out)


@register
class Say(Action):
    """Have the robot speak ``text``, placeholders filled from the blackboard; see the module."""

    requires = (ROBOT,)

    def __init__(self, text: str) -> None:
        if not text.strip():
            raise ValueError("text is empty: give the sentence to say")
        self.text = text
        self.template = Template.parse(text)
        self.reason = ""
        self.said = ""
        """The last sentence said."""

    @override
    def tick(self) -> Status:
        try:
            sentence = self.template.render(self.blackboard)
        except (KeyError, ValueError) as exc:
            self.reason = str(exc.args[0]) if exc.args else str(exc)
            return FAILURE
        perceiving_robot_of(self).say(sentence)
        self.said, self.reason = sentence, ""
        return SUCCESS
