"""Small ARNL maps written by the tests: rooms, doors, boxes (millimetres, as in real files)."""

from __future__ import annotations

from pathlib import Path


def room_map(cairns: list[str], lines: list[tuple[int, int, int, int]] | None = None,
             points: list[tuple[int, int]] | None = None) -> str:
    """A 10 x 6 m room split by a wall at x = 5 m with a 1.2 m door at y 2.4..3.6 m."""
    walls = [(0, 0, 10000, 0), (10000, 0, 10000, 6000), (10000, 6000, 0, 6000), (0, 6000, 0, 0),
             (5000, 0, 5000, 2400), (5000, 3600, 5000, 6000)]
    walls += lines or []
    text = ["2D-Map", "Resolution: 20", *[f"Cairn: {cairn}" for cairn in cairns], "LINES"]
    text += [" ".join(str(value) for value in wall) for wall in walls]
    text += ["DATA", *[f"{x} {y}" for x, y in points or []]]
    return "\n".join(text) + "\n"


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(text)
    return path


def corridor_map(width: float, length: float = 14.0, cairns: list[str] | None = None) -> str:
    """A straight corridor ``length`` m long and ``width`` m wide along x, closed at both ends.

    Its floor runs from (0, 0) to (``length``, ``width``); ``cairns`` as in :func:`room_map`.
    """
    w, n = round(width * 1000), round(length * 1000)
    walls = [(0, 0, n, 0), (n, 0, n, w), (n, w, 0, w), (0, w, 0, 0)]
    text = ["2D-Map", "Resolution: 20", *[f"Cairn: {cairn}" for cairn in cairns or []], "LINES"]
    text += [" ".join(str(value) for value in wall) for wall in walls]
    return "\n".join([*text, "DATA"]) + "\n"
