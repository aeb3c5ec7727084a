"""Write the bundled campus map, ``src/cyborg/app/data/campus.map`` (ARNL 2D-Map format).

A small campus the project drew for itself: two buildings and a courtyard, about 50 x 26 m.

* West building: a corridor with a lecture hall and a library to the north, a lab (with the
  charging dock), an office and a stairwell (forbidden) to the south.
* Courtyard: open, with two planters (obstacles) and a flower bed behind a forbidden line.
* East building: a cafeteria and, behind it, a workshop.

Walls are LINES; DATA holds points every 10 cm along them, as a laser scan of the walls would.
Run ``python3 scripts/make_campus_map.py`` after changing the layout; the output is committed.
"""

from __future__ import annotations

import math
from pathlib import Path

OUT = Path(__file__).resolve().parents[1] / "src" / "cyborg" / "app" / "data" / "campus.map"
DOOR = 1.6  # metres


def wall(x0: float, y0: float, x1: float, y1: float,
         doors: tuple[float, ...] = ()) -> list[tuple[float, float, float, float]]:
    """A straight wall with door openings centred at the given distances from its start."""
    length = math.hypot(x1 - x0, y1 - y0)
    ux, uy = (x1 - x0) / length, (y1 - y0) / length
    pieces, at = [], 0.0
    for centre in sorted(doors):
        end = centre - DOOR / 2
        if end > at:
            pieces.append((at, end))
        at = centre + DOOR / 2
    if at < length:
        pieces.append((at, length))
    return [(x0 + ux * a, y0 + uy * a, x0 + ux * b, y0 + uy * b) for a, b in pieces]


def box(x0: float, y0: float, x1: float, y1: float) -> list[tuple[float, float, float, float]]:
    return [(x0, y0, x1, y0), (x1, y0, x1, y1), (x1, y1, x0, y1), (x0, y1, x0, y0)]


def layout() -> list[tuple[float, float, float, float]]:
    lines = []
    # West building 0..20 x 0..14; corridor y 6..8
    lines += wall(0, 0, 20, 0)
    lines += wall(0, 14, 20, 14)
    lines += wall(0, 0, 0, 14)
    lines += wall(20, 0, 20, 14, doors=(7.0,))  # main entrance to the courtyard
    lines += wall(0, 6, 20, 6, doors=(4.0, 11.0))  # lab and office doors (stairwell is open)
    lines += wall(0, 8, 20, 8, doors=(5.0, 15.0))  # lecture hall and library doors
    lines += wall(8, 0, 8, 6)
    lines += wall(14, 0, 14, 6)
    lines += wall(10, 8, 10, 14)
    # East building 32..48 x 0..20: cafeteria below y 12, workshop above
    lines += wall(32, 0, 48, 0)
    lines += wall(32, 20, 48, 20)
    lines += wall(32, 0, 32, 20, doors=(7.0,))
    lines += wall(48, 0, 48, 20)
    lines += wall(32, 12, 48, 12, doors=(12.0,))
    # Campus fence around the courtyard
    lines += wall(20, -3, 32, -3)
    lines += wall(20, 23, 32, 23)
    lines += wall(20, -3, 20, 0)
    lines += wall(32, -3, 32, 0)
    lines += wall(20, 14, 20, 23)
    lines += wall(32, 20, 32, 23)
    # Planters in the courtyard
    lines += box(24.0, 2.0, 26.0, 4.0)
    lines += box(26.0, 10.0, 28.0, 12.0)
    return lines


GOALS = [  # kind, x, y, heading degrees, description, name
    ("Dock", 2.0, 1.2, -90.0, "Charging station in the lab", "Charger"),
    ("RobotHome", 2.0, 3.0, 90.0, "Where the robot starts", "Home"),
    ("GoalWithHeading", 5.0, 11.5, 90.0, "Lecture hall, facing the board", "Lecture hall"),
    ("GoalWithHeading", 15.0, 11.0, 0.0, "Library, by the shelves", "Library"),
    ("Goal", 11.0, 3.0, 0.0, "The office", "Office"),
    ("Goal", 17.0, 7.0, 0.0, "Corridor by the stairs", "Corridor"),
    ("Goal", 26.0, 7.0, 0.0, "Middle of the courtyard", "Courtyard"),
    ("GoalWithHeading", 40.0, 6.0, 180.0, "Cafeteria, facing the entrance", "Cafeteria"),
    ("Goal", 40.0, 16.0, 0.0, "The workshop", "Workshop"),
]
FORBIDDEN_AREAS = [("Stairwell", 14.3, 0.3, 19.7, 5.7)]
FORBIDDEN_LINES = [(28.0, 17.0, 31.5, 17.0)]  # flower bed edge


def mm(value: float) -> int:
    return round(value * 1000)


def render() -> str:
    lines = layout()
    points: list[tuple[int, int]] = []
    for x0, y0, x1, y1 in lines:
        steps = max(1, round(math.hypot(x1 - x0, y1 - y0) / 0.1))
        points += [(mm(x0 + (x1 - x0) * i / steps), mm(y0 + (y1 - y0) * i / steps))
                   for i in range(steps + 1)]
    points = sorted(set(points))
    xs = [p[0] for p in points]
    ys = [p[1] for p in points]
    lxs = [mm(v) for line in lines for v in (line[0], line[2])]
    lys = [mm(v) for line in lines for v in (line[1], line[3])]
    out = [
        "2D-Map",
        f"MinPos: {min(xs)} {min(ys)}",
        f"MaxPos: {max(xs)} {max(ys)}",
        f"NumPoints: {len(points)}",
        f"LineMinPos: {min(lxs)} {min(lys)}",
        f"LineMaxPos: {max(lxs)} {max(lys)}",
        f"NumLines: {len(lines)}",
        "Resolution: 100",
        'MapInfo: GoalType "Name=Goal" "Label=Goal"',
        'MapInfo: DockType "Name=Dock" "Label=Dock"',
    ]
    for kind, x, y, heading, description, name in GOALS:
        out.append(f'Cairn: {kind} {mm(x)} {mm(y)} {heading:.1f} "{description}" ICON "{name}"')
    for name, x0, y0, x1, y1 in FORBIDDEN_AREAS:
        out.append(f'Cairn: ForbiddenArea 0 0 0.0 "" ICON "{name}" '
                   f"{mm(x0)} {mm(y0)} {mm(x1)} {mm(y1)}")
    for x0, y0, x1, y1 in FORBIDDEN_LINES:
        out.append(f'Cairn: ForbiddenLine {mm(x0)} {mm(y0)} 0.0 "" ICON "" '
                   f"{mm(x0)} {mm(y0)} {mm(x1)} {mm(y1)}")
    out.append("LINES")
    out += [f"{mm(a)} {mm(b)} {mm(c)} {mm(d)}" for a, b, c, d in lines]
    out.append("DATA")
    out += [f"{x} {y}" for x, y in points]
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    OUT.write_text(render())
    print(f"wrote {OUT}")
