"""``BlackboardCompare{key, value, equal}``: tick the child only when a blackboard entry matches.

The decorator compares the global blackboard entry ``key`` with ``value``. When the comparison
says what ``equal`` asks for (equal by default; ``equal: false`` for "not equal"), it ticks its
child and returns the child's status; otherwise it returns FAILURE and a RUNNING child is
halted. The editor stores every property as typed in the form, so ``value`` ``"3"`` matches
the number 3 and ``"true"`` matches True; a missing key equals only an empty ``value``.
This is the node the 2018 system sketched but never got to run.
"""

from __future__ import annotations

from typing import Any

from typing_extensions import override

from cyborg.bt import FAILURE, Decorator, Status, register


@register
class BlackboardCompare(Decorator):
    """Ticks its child only while the global blackboard entry ``key`` matches ``value``.

    With ``equal`` false, only while it does not; otherwise it returns FAILURE and halts a
    RUNNING child. Values compare as :func:`same` does; an empty ``key`` raises ValueError.
    """

    def __init__(self, key: str, value: Any = "", equal: bool = True) -> None:
        if not key:
            raise ValueError("key is empty: name the blackboard entry to compare")
        self.key, self.value, self.equal = key, value, equal

    def matches(self) -> bool:
        """Whether the entry now says what ``equal`` asks for (the child may run)."""
        return same(self.blackboard.get(self.key), self.value) == self.equal

    @override
    def tick(self) -> Status:
        if self.matches():
            return self.child.execute()
        self.child.halt()
        return FAILURE


def same(actual: Any, wanted: Any) -> bool:
    """Equality that forgives the editor's strings: ``"3" ~ 3``, ``"true" ~ True``."""
    if actual is None:
        return wanted in (None, "")
    if actual == wanted:
        return True
    if isinstance(wanted, str):
        text = wanted.strip()
        if isinstance(actual, bool):
            return text.lower() == str(actual).lower()
        if isinstance(actual, int | float):
            try:
                return float(text) == float(actual)
            except ValueError:
                return False
        return str(actual) == text
    return False
