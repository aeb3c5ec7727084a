"""Stand-ins for nodes that have no Python class yet.

While a tree is being drawn, its custom nodes are often not written yet. With
``--stub-missing STATUS`` (:func:`cyborg.bt.load_tree` ``stub_missing=``) each such node is
replaced by a stub so the tree's logic can be run and watched: an action or condition returns
STATUS, a decorator returns its child's status, a composite behaves as a Sequence. The category
comes from the file's ``custom_nodes`` entry, or from how the block was connected.
"""

from __future__ import annotations

from typing_extensions import override

from cyborg.bt.composites import Sequence
from cyborg.bt.editor_format import NodeDefinition, NodeSpec
from cyborg.bt.node import Action, Condition, Decorator, Node
from cyborg.bt.status import Status


class StubLeaf(Action):
    """An action or condition with no implementation: returns a fixed status."""

    result: Status = Status.SUCCESS

    @override
    def tick(self) -> Status:
        return self.result


class StubCondition(Condition):
    """A condition with no implementation: returns a fixed status."""

    result: Status = Status.SUCCESS

    @override
    def tick(self) -> Status:
        return self.result


class StubDecorator(Decorator):
    """A decorator with no implementation: passes its child's status through."""

    @override
    def tick(self) -> Status:
        return self.child.execute()


class StubComposite(Sequence):
    """A composite with no implementation: behaves as a Sequence."""


def stub_class(spec: NodeSpec, definition: NodeDefinition | None,
               result: Status) -> type[Node]:
    """The stub class for ``spec``: by declared category, else by how it was connected.

    How the block is connected wins where the two disagree (behavior3 v1 lets an action
    have a child and a decorator have none): a leaf with children stands in as their parent,
    a decorator without a child as a leaf.
    """
    category = definition.category if definition and definition.category else spec.shape
    if spec.children and category in ("action", "condition"):
        category = spec.shape
    elif not spec.children and category == "decorator":
        category = "action"
    if category == "composite":
        return StubComposite
    if category == "decorator":
        return StubDecorator
    leaf: type[StubLeaf | StubCondition] = (
        StubCondition if category == "condition" else StubLeaf)
    return type(leaf.__name__, (leaf,), {"result": result})
