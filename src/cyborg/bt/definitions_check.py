"""Checking a project's declared custom nodes against the node registry.

behavior3editor keeps the nodes a project may use in its ``custom_nodes`` (0.3.0) or its node
definitions (1.x). When every tree of a project is checked (``cyborg bt validate``), each
declaration is compared with the Python classes registered: a declared node without a class,
and a node declared in one category but implemented in another, are warnings.
"""

from __future__ import annotations

from cyborg.bt.editor_format import ProjectSpec
from cyborg.bt.problems import Problem, Severity
from cyborg.bt.registry import NodeRegistry


def check_definitions(project: ProjectSpec, registry: NodeRegistry,
                      stubbing: bool) -> list[Problem]:
    """The warnings about ``project``'s declared nodes; ``stubbing``: stubs stand in.

    A behavior3 1.x node-config file is the editor's whole palette, so only the nodes its
    trees use are checked; a missing class there is an error of each use, reported elsewhere.
    """
    problems: list[Problem] = []
    used = {node.name for tree in project.trees for node in tree.nodes.values()}
    for definition in project.definitions:
        if project.kind == "v1" and definition.name not in used:
            continue
        node_type = registry.get(definition.name)
        where = Problem("", definition.source or project.source, definition.line,
                        node_title=definition.name,
                        field="node definitions" if project.kind == "v1" else "custom_nodes")
        if node_type is None:
            if not stubbing and project.kind != "v1":  # v1: an error per use
                problems.append(_at(where, f"custom node {definition.name!r} is declared "
                                           "but no Python class is registered for it"))
            continue
        if definition.category and definition.category != node_type.category.value:
            problems.append(_at(
                where, f"custom node {definition.name!r} is declared as a {definition.category}"
                f" but {node_type.cls.__name__} is a {node_type.category.value}"))
    return problems


def _at(where: Problem, message: str) -> Problem:
    return Problem(message, where.source, where.line, None, None, None, where.node_title,
                   where.field, Severity.WARNING)
