"""Custom nodes: registered by decorator or entry point, properties bound by signature."""

from __future__ import annotations

import json
import sys
import textwrap
from enum import Enum
from pathlib import Path
from typing import Literal

import pytest

from cyborg.bt import (
    Action,
    Condition,
    Decorator,
    NodeRegistry,
    Status,
    TreeLoadError,
    default_registry,
    loads_tree,
    register,
)
from cyborg.bt.properties import bind, camel_case, signature_of, snake_case
from tests.builders import N, tree_json


class Mode(Enum):
    FAST = "fast"
    SAFE = "safe"


class Configured(Action):
    def __init__(self, max_speed: float, mode: Mode = Mode.SAFE, tags: list[str] | None = None,
                 side: Literal["left", "right"] = "left", enabled: bool = True) -> None:
        self.max_speed = max_speed
        self.mode = mode
        self.tags = tags
        self.side = side
        self.enabled = enabled

    def tick(self) -> Status:
        return Status.SUCCESS


def test_register_decorator_uses_editor_name_with_punctuation() -> None:
    @register("Bedtime?")
    class Bedtime(Condition):
        def __init__(self, hour: int = 22) -> None:
            self.hour = hour

        def tick(self) -> bool:  # type: ignore[override]
            return self.hour >= 22

    reg = default_registry(entry_points=False)
    assert reg.get("Bedtime?") is not None
    spec = N("Sequence", N("Bedtime?", id="b", hour=23), id="s")
    tree = loads_tree(json.dumps(tree_json(spec, reg=reg)), registry=reg)
    assert tree.tick().status is Status.SUCCESS
    assert tree.by_uid["b"].category.value == "condition"


def test_register_without_name_uses_class_name() -> None:
    @register
    class PlainName(Action):
        def tick(self) -> Status:
            return Status.FAILURE

    assert default_registry(entry_points=False).get("PlainName") is not None


def test_camel_and_snake_names_are_both_accepted() -> None:
    assert snake_case("maxLoop") == "max_loop"
    assert snake_case("successThreshold") == "success_threshold"
    assert camel_case("max_speed") == "maxSpeed"
    signature = signature_of(Configured)
    for properties in ({"maxSpeed": 1}, {"max_speed": 1}):
        binding = bind(signature, properties)
        assert binding.errors == []
        assert binding.kwargs == {"max_speed": 1.0}


@pytest.mark.parametrize(("properties", "expected"), [
    ({"maxSpeed": "0.5"}, {"max_speed": 0.5}),
    ({"maxSpeed": 1, "mode": "fast"}, {"max_speed": 1.0, "mode": Mode.FAST}),
    ({"maxSpeed": 1, "mode": "FAST"}, {"max_speed": 1.0, "mode": Mode.FAST}),
    ({"maxSpeed": 1, "tags": ["a", "b"]}, {"max_speed": 1.0, "tags": ["a", "b"]}),
    ({"maxSpeed": 1, "tags": None}, {"max_speed": 1.0, "tags": None}),
    ({"maxSpeed": 1, "side": "right"}, {"max_speed": 1.0, "side": "right"}),
    ({"maxSpeed": 1, "enabled": "false"}, {"max_speed": 1.0, "enabled": False}),
])
def test_values_are_converted_by_type_hint(properties: dict[str, object],
                                           expected: dict[str, object]) -> None:
    binding = bind(signature_of(Configured), properties)
    assert binding.errors == []
    assert binding.kwargs == expected


@pytest.mark.parametrize(("properties", "field", "words"), [
    ({}, "maxSpeed", "missing property 'maxSpeed' (float)"),
    ({"maxSpeed": "fast"}, "maxSpeed", "expected float, got 'fast'"),
    ({"maxSpeed": 1, "mode": "turbo"}, "mode", "expected one of 'fast', 'safe'"),
    ({"maxSpeed": 1, "tags": [1]}, "tags", "expected"),
    ({"maxSpeed": 1, "side": "up"}, "side", "expected one of 'left', 'right'"),
    ({"maxSpeed": 1, "enabled": 1}, "enabled", "expected bool"),
])
def test_bad_values_name_the_field(properties: dict[str, object], field: str,
                                   words: str) -> None:
    binding = bind(signature_of(Configured), properties)
    assert [f for f, _ in binding.errors] == [field]
    assert words in binding.errors[0][1]


def test_kwargs_node_takes_any_property() -> None:
    class Open(Action):
        def __init__(self, **options: object) -> None:
            self.options = options

        def tick(self) -> Status:
            return Status.SUCCESS

    binding = bind(signature_of(Open), {"anything": 1})
    assert binding.kwargs == {"anything": 1} and binding.warnings == []


def test_registry_rejects_non_nodes() -> None:
    reg = NodeRegistry()
    with pytest.raises(TypeError):
        reg.add(int)


def test_custom_decorator_node() -> None:
    class Twice(Decorator):
        def tick(self) -> Status:
            self.child.execute()
            return self.child.execute()

    reg = default_registry(entry_points=False)
    reg.add(Twice)
    tree = loads_tree(json.dumps(tree_json(N("Twice", N("Succeeder")), reg=reg)), registry=reg)
    assert tree.tick().status is Status.SUCCESS


def test_entry_points_add_nodes(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "greeting_nodes.py").write_text(textwrap.dedent("""
        from cyborg.bt import Action, Status, register

        class Greet(Action):
            def __init__(self, name: str = "world") -> None:
                self.name = name
            def tick(self) -> Status:
                return Status.SUCCESS

        @register("Wave hand")
        class Wave(Action):
            def tick(self) -> Status:
                return Status.RUNNING
        """))
    dist = tmp_path / "greeting_nodes-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: greeting-nodes\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text(
        "[cyborg.nodes]\nmodule = greeting_nodes\nGreet = greeting_nodes:Greet\n"
        "broken = greeting_nodes_missing\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    reg = default_registry(entry_points=False)
    problems = reg.load_entry_points()
    assert reg.get("Greet") is not None
    assert reg.get("Wave hand") is not None
    assert reg.get("Greet").origin == "entry point Greet"  # type: ignore[union-attr]
    assert len(problems) == 1 and "broken" in problems[0]
    monkeypatch.delitem(sys.modules, "greeting_nodes")


def test_unknown_name_after_entry_points_still_lists_names() -> None:
    with pytest.raises(TreeLoadError, match=r"registered: .*Sequence"):
        loads_tree(json.dumps(tree_json(N("NoSuchNode"))), registry=default_registry())


def test_import_modules_names_the_failing_module() -> None:
    from cyborg.bt.registry import NodeModuleError

    reg = default_registry(entry_points=False)
    with pytest.raises(NodeModuleError, match=r"cannot import node module 'no_such_nodes': "
                                               r"ModuleNotFoundError"):
        reg.import_modules(["no_such_nodes"])
