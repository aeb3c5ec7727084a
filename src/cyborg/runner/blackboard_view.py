"""The blackboard as the monitor is shown it: strict JSON of bounded size, whatever it holds.

A node may write anything: a list that holds itself (``Push`` with input ``["l", "l"]``), an
integer of 5,000 digits (past which ``json.dumps`` raises), a text of megabytes, objects
nested a thousand deep. :func:`blackboard_json` shows what it can and says what it leaves out,
``"(not shown: ...)"`` in the value's place, so the monitor's blackboard never goes stale on
one bad value::

    scopes = {"global": {"l": looped, "n": 10 ** 5000}}
    blackboard_json(scopes)   # '{"global": {"l": ["(not shown: it holds itself)"], ...'

Keys become strings, ``inf`` and ``nan`` strings too, other objects their ``repr`` (cut).
"""

from __future__ import annotations

import json
import math
from typing import Any

from cyborg.bt.js_values import js_number

MAX_CHARACTERS = 1 << 20
"""Text the whole blackboard may take, about: what comes after is not shown."""
MAX_DEPTH = 32
"""Deepest nesting of lists and objects shown."""
MAX_ITEMS = 1000
"""Items of one list or object shown; the rest are counted."""
MAX_TEXT = 10_000
"""Characters of one text shown; the rest are counted."""


def blackboard_json(scopes: dict[str, Any]) -> str:
    """``scopes`` (``Blackboard.as_dict()``) as strict JSON text, about 1 MiB at most."""
    return json.dumps(_Shower().show(scopes, 0, ()), sort_keys=True)


class _Shower:
    def __init__(self) -> None:
        self.left = MAX_CHARACTERS

    def show(self, value: Any, depth: int, holding: tuple[int, ...]) -> Any:
        if self.left <= 0:
            return f"(not shown: the blackboard is past {MAX_CHARACTERS:,} characters)"
        if value is None or isinstance(value, bool):
            self.left -= 5
            return value
        if isinstance(value, int):
            return self.integer(value)
        if isinstance(value, float):
            self.left -= 24
            return value if math.isfinite(value) else str(value)
        if isinstance(value, str):
            return self.text(value)
        if isinstance(value, dict | list | tuple | set | frozenset):
            if id(value) in holding:
                return "(not shown: it holds itself)"
            if depth >= MAX_DEPTH:
                return f"(not shown: nested deeper than {MAX_DEPTH})"
            return self.container(value, depth + 1, (*holding, id(value)))
        return self.text(repr(value))

    def integer(self, value: int) -> Any:
        """As JavaScript holds it (:func:`~cyborg.bt.js_values.js_number`), or not at all."""
        self.left -= 20
        shown = js_number(value)
        if math.isfinite(shown):
            return shown
        return f"(not shown: an integer of about {int(value.bit_length() * 0.30103):,} digits)"

    def text(self, value: str) -> str:
        shown = value if len(value) <= MAX_TEXT else (
            f"{value[:MAX_TEXT]}… ({len(value):,} characters)")
        self.left -= len(shown) + 2
        return shown

    def container(self, value: Any, depth: int, holding: tuple[int, ...]) -> Any:
        items = list(value.items()) if isinstance(value, dict) else list(value)
        if isinstance(value, dict):
            shown: Any = {}
            for key, item in items[:MAX_ITEMS]:
                if self.left <= 0:
                    break
                self.left -= 4  # the quotes, colon and comma around the key
                shown[self.text(str(key))] = self.show(item, depth, holding)
            if len(shown) < len(items):
                shown["(not shown)"] = f"{len(items) - len(shown):,} more entries{self.why()}"
            return shown
        listed: list[Any] = []
        for item in items[:MAX_ITEMS]:
            if self.left <= 0:
                break
            self.left -= 2  # the comma and space between items
            listed.append(self.show(item, depth, holding))
        if len(listed) < len(items):
            listed.append(f"(not shown: {len(items) - len(listed):,} more items{self.why()})")
        return listed

    def why(self) -> str:
        """Why a container's last entries are not shown, when it is not their number."""
        return f": the blackboard is past {MAX_CHARACTERS:,} characters" if self.left <= 0 \
            else ""
