"""A report's HTML read back with the standard library's parser, for the tests to query.

Every element is kept with its attributes, its text and the ``id`` of the robot section it
lies in, so a test asks "the goals tally of robot 0" or "every polyline of class trajectory"
without relying on the page's layout.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from html.parser import HTMLParser

VOID = {"meta", "br", "img", "input", "link", "hr", "col", "area", "base", "source", "wbr",
        "embed", "param", "track"}


@dataclass
class Element:
    tag: str
    attrs: dict[str, str]
    robot: str
    """The id of the robot section it lies in ("" outside one)."""
    sections: tuple[str, ...]
    """The classes of the sections it lies in, outermost first."""
    text: str = ""
    children: list[Element] = field(default_factory=list)

    @property
    def classes(self) -> set[str]:
        return set(self.attrs.get("class", "").split())

    def all_text(self) -> str:
        return self.text + "".join(child.all_text() for child in self.children)


class _Reader(HTMLParser):
    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.elements: list[Element] = []
        self.stack: list[Element] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        values = {name: value or "" for name, value in attrs}
        robot = next((item.attrs.get("id", "") for item in reversed(self.stack)
                      if item.tag == "section" and "robot" in item.classes), "")
        sections = tuple(item.attrs.get("class", "") for item in self.stack
                         if item.tag == "section")
        if tag == "section" and "robot" in values.get("class", "").split():
            robot = values.get("id", "")
        element = Element(tag, values, robot, sections)
        if self.stack:
            self.stack[-1].children.append(element)
        self.elements.append(element)
        if tag not in VOID:
            self.stack.append(element)

    def handle_startendtag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.handle_starttag(tag, attrs)
        if tag not in VOID and self.stack and self.stack[-1].tag == tag:
            self.stack.pop()

    def handle_endtag(self, tag: str) -> None:
        for depth in range(len(self.stack) - 1, -1, -1):
            if self.stack[depth].tag == tag:
                del self.stack[depth:]
                return

    def handle_data(self, data: str) -> None:
        if self.stack:
            self.stack[-1].children.append(Element("#text", {}, "", (), data))


@dataclass
class Page:
    elements: list[Element]
    text: str

    def find(self, tag: str, css: str = "", *, robot: str | None = None,
             section: str = "") -> list[Element]:
        """Elements of ``tag`` (with class ``css``, in robot section ``robot``, inside a
        section of class ``section``)."""
        return [element for element in self.elements
                if element.tag == tag and (not css or css in element.classes)
                and (robot is None or element.robot == robot)
                and (not section or section in element.sections)]

    def one(self, tag: str, css: str = "", **where: str) -> Element:
        found = self.find(tag, css, **where)
        assert len(found) == 1, (tag, css, where, len(found))
        return found[0]

    def section_text(self, css: str, robot: str) -> str:
        return " ".join(element.all_text() for element in self.find("section", css, robot=robot))


def read_page(text: str) -> Page:
    reader = _Reader()
    reader.feed(text)
    reader.close()
    return Page(reader.elements, text)


def polyline_points(element: Element) -> list[tuple[float, float]]:
    pairs = element.attrs["points"].split()
    return [(float(x), float(y)) for x, y in (pair.split(",") for pair in pairs)]
