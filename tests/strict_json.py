"""Reading what a page or a bus peer would receive as strict JSON, as a browser's parser does.

Python's ``json`` reads ``NaN`` and ``Infinity``, which are not JSON: a browser's
``JSON.parse`` refuses the whole message. Tests that check what the product sends read it
with :func:`strict_loads`, which fails the test on either.
"""

from __future__ import annotations

import json
from typing import Any, NoReturn


def _refuse(name: str) -> NoReturn:
    raise AssertionError(f"{name} was sent, which JSON does not have")


def strict_loads(text: str) -> Any:
    """``json.loads(text)``, failing the test on ``NaN``, ``Infinity`` or ``-Infinity``."""
    return json.loads(text, parse_constant=_refuse)
