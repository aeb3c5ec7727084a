r"""The ``services`` property of a composite: the text that declares its services.

In behavior3editor a composite carries its services as one text property, ``services``::

    BatteryWatch(interval=1.0); ClosestGoal(key=closest, run_on_activation=true)

The grammar, spaces allowed between any two tokens::

    declaration := call { ";" call } [ ";" ]          (blank text: no services)
    call        := name [ "(" [ option { "," option } [ "," ] ] ")" ]
    option      := name "=" value
    name        := a Python identifier: a letter or "_", then letters, digits, "_"
    value       := number | quoted | "true" | "false" | word
    number      := [+-] digits [ "." digits ] [ ("e" | "E") [+-] digits ]   (or ".5")
    quoted      := '"' ... '"'  or  "'" ... "'"   (backslash escapes \\ \" \' \n \t)
    word        := a letter, "_" or "/", then letters, digits, "_", ".", "/", "-"

A number with a "." or an exponent is a float, else an int; a *word* is a string
(``key=closest`` is ``key="closest"``); ``true`` and ``false`` are booleans (in any case).
Each option is given once per call and each service once per composite. Errors carry the
1-based column in the property's text, so the editor's user finds the spot.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")
_WORD = re.compile(r"[A-Za-z_/][A-Za-z0-9_./-]*")
_ESCAPES = {"\\": "\\", '"': '"', "'": "'", "n": "\n", "t": "\t"}
_SEPARATORS = ",);"


@dataclass(frozen=True)
class ServiceCall:
    """One service named in a declaration, with the options given to it."""

    name: str
    options: dict[str, Any]
    """Option name as written -> its value (int, float, str or bool)."""
    column: int
    """1-based column of the name in the property's text."""
    option_columns: dict[str, int] = field(default_factory=dict)
    """Option name -> 1-based column where it is written."""
    text: str = ""
    """The call as written, spaces trimmed (for monitors)."""


class ServiceSyntaxError(ValueError):
    """A declaration that does not follow the grammar; :attr:`column` is 1-based."""

    def __init__(self, message: str, column: int) -> None:
        super().__init__(f"column {column}: {message}")
        self.message = message
        self.column = column


def parse_services(text: str) -> list[ServiceCall]:
    """The calls of a ``services`` declaration, in order; raises :class:`ServiceSyntaxError`."""
    return _Parser(text).declaration()


class _Parser:
    def __init__(self, text: str) -> None:
        self.text = text
        self.at = 0

    # ------------------------------------------------------------------ helpers
    def error(self, message: str, at: int | None = None) -> ServiceSyntaxError:
        return ServiceSyntaxError(message, (self.at if at is None else at) + 1)

    def skip_spaces(self) -> None:
        text, at = self.text, self.at
        while at < len(text) and text[at].isspace():
            at += 1
        self.at = at

    def peek(self) -> str:
        self.skip_spaces()
        return self.text[self.at] if self.at < len(self.text) else ""

    def found(self) -> str:
        char = self.peek()
        return "the end of the text" if not char else repr(char)

    def name(self, what: str) -> tuple[str, int]:
        self.skip_spaces()
        match = _NAME.match(self.text, self.at)
        if match is None:
            raise self.error(f"expected {what}, found {self.found()}")
        self.at = match.end()
        return match.group(), match.start() + 1

    # ------------------------------------------------------------------ grammar
    def declaration(self) -> list[ServiceCall]:
        calls: list[ServiceCall] = []
        seen: dict[str, int] = {}
        while self.peek():
            if self.peek() == ";":  # a blank call between two ';'
                self.at += 1
                continue
            start = self.at
            call = self.call()
            if call.name in seen:
                raise self.error(f"service {call.name!r} is declared twice on this composite "
                                 f"(first at column {seen[call.name]})", start)
            seen[call.name] = call.column
            calls.append(call)
            char = self.peek()
            if char == ";":
                self.at += 1
            elif char:
                raise self.error(f"expected ';' between two services, found {char!r}")
        return calls

    def call(self) -> ServiceCall:
        start = self.at
        name, column = self.name("a service name")
        options: dict[str, Any] = {}
        columns: dict[str, int] = {}
        if self.peek() == "(":
            self.at += 1
            while self.peek() != ")":
                if not self.peek():
                    raise self.error(f"the options of {name!r} are not closed: add ')'")
                key, key_column = self.name("an option name")
                if key in options:
                    raise self.error(f"option {key!r} is given twice (first at column "
                                     f"{columns[key]})", key_column - 1)
                if self.peek() != "=":
                    raise self.error(f"expected '=' after option {key!r}, found {self.found()}")
                self.at += 1
                options[key] = self.value(key)
                columns[key] = key_column
                char = self.peek()
                if char == ",":
                    self.at += 1
                elif char != ")":
                    raise self.error(f"expected ',' or ')' after the value of {key!r}, "
                                     f"found {self.found()}")
            self.at += 1
        return ServiceCall(name, options, column, columns, self.text[start:self.at].strip())

    def value(self, key: str) -> Any:
        char = self.peek()
        start = self.at
        if char in ("'", '"'):
            return self.quoted(char)
        number = _NUMBER.match(self.text, start)
        if number is not None and self.ends_here(number.end()):
            self.at = number.end()
            written = number.group()
            if any(mark in written for mark in ".eE"):
                return float(written)
            return int(written)
        word = _WORD.match(self.text, start)
        if word is not None and self.ends_here(word.end()):
            self.at = word.end()
            lowered = word.group().lower()
            return lowered == "true" if lowered in ("true", "false") else word.group()
        end = start
        while end < len(self.text) and self.text[end] not in _SEPARATORS:
            end += 1
        bad = self.text[start:end].strip()
        if not bad:
            raise self.error(f"option {key!r} has no value after '='")
        raise self.error(f"{bad!r} is not a value for option {key!r}: write a number, true, "
                         "false, a word of letters, digits, '_', '.', '/' or '-', or quote "
                         "the text")

    def ends_here(self, end: int) -> bool:
        rest = self.text[end:].lstrip()
        return not rest or rest[0] in _SEPARATORS

    def quoted(self, quote: str) -> str:
        text = self.text
        opened = self.at
        at = opened + 1
        parts: list[str] = []
        while at < len(text):
            char = text[at]
            if char == quote:
                self.at = at + 1
                return "".join(parts)
            if char == "\\":
                escaped = text[at + 1:at + 2]
                if escaped not in _ESCAPES:
                    raise self.error(f"unknown escape '\\{escaped}' in quoted text (known: "
                                     "\\\\ \\\" \\' \\n \\t)", at)
                parts.append(_ESCAPES[escaped])
                at += 2
                continue
            parts.append(char)
            at += 1
        raise self.error(f"quoted text is not closed: add {quote}", opened)
