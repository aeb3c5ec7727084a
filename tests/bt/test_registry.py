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


def _installed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, module: str,
               entry_points: str) -> None:
    """The module ``module`` (already written in ``tmp_path``) installed as pip installs a
    package: its dist-info declares ``entry_points``, and it is on the path."""
    dist = tmp_path / f"{module}-1.0.dist-info"
    dist.mkdir()
    name = module.replace("_", "-")
    (dist / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text(entry_points)
    monkeypatch.syspath_prepend(str(tmp_path))


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
    _installed(tmp_path, monkeypatch, "greeting_nodes",
               "[cyborg.nodes]\nmodule = greeting_nodes\nGreet = greeting_nodes:Greet\n"
               "broken = greeting_nodes_missing\n")
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


# ------------------------------------------------------------------------- names already taken
@pytest.fixture
def own_registered(monkeypatch: pytest.MonkeyPatch) -> NodeRegistry:
    """A copy of the decorator's registry for the test, so that its registrations stay there."""
    from cyborg.bt import registry as registry_module

    copy = registry_module._REGISTERED.copy()
    monkeypatch.setattr(registry_module, "_REGISTERED", copy)
    return copy


def test_a_stock_nodes_name_is_refused_naming_both_classes_and_where_each_comes_from() -> None:
    from cyborg.bt.named_registry import NameTakenError

    class Sequence(Action):
        def tick(self) -> Status:
            return Status.SUCCESS

    reg = default_registry(entry_points=False)
    with pytest.raises(NameTakenError) as refused:
        reg.add(Sequence)
    message = str(refused.value)
    assert "node name 'Sequence' is taken by cyborg.bt.composites.Sequence (from stock)" in message
    assert f"{__name__}.{Sequence.__qualname__} (from {__name__}) would replace it" in message
    assert "override=True" in message
    assert reg.get("Sequence").cls.__module__ == "cyborg.bt.composites"  # type: ignore[union-attr]
    assert reg.add(Sequence, override=True).cls is Sequence
    assert reg.get("Sequence").cls is Sequence  # type: ignore[union-attr]


def test_the_decorator_refuses_a_taken_name_unless_told_to_override(
        own_registered: NodeRegistry) -> None:
    from cyborg.bt.named_registry import NameTakenError

    with pytest.raises(NameTakenError, match=r"'Succeeder' is taken by cyborg\.bt\.leaves"):
        @register("Succeeder")
        class Quiet(Action):
            def tick(self) -> Status:
                return Status.FAILURE

    @register("Succeeder", override=True)
    class Loud(Action):
        def tick(self) -> Status:
            return Status.FAILURE

    assert own_registered.get("Succeeder").cls is Loud  # type: ignore[union-attr]
    assert default_registry(entry_points=False).get("Succeeder").cls is Loud  # type: ignore[union-attr]


def test_an_override_keeps_the_name_whichever_class_is_registered_first() -> None:
    class Mine(Action):
        def tick(self) -> Status:
            return Status.SUCCESS

    class BuiltIn(Action):
        def tick(self) -> Status:
            return Status.SUCCESS

    reg = NodeRegistry()
    reg.add(Mine, "Speak", override=True)
    assert reg.add(BuiltIn, "Speak").cls is Mine  # registered later, not overriding: kept out
    assert reg.copy().add(BuiltIn, "Speak").cls is Mine
    assert reg.add(Mine, "Speak").cls is Mine  # the same class again is no conflict


def test_an_entry_point_registering_a_taken_name_is_skipped_with_a_message_naming_both(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, own_registered: NodeRegistry) -> None:
    (tmp_path / "clashing_nodes.py").write_text(textwrap.dedent("""
        from cyborg.bt import Action, Status, register

        @register("Wait")
        class Wait(Action):
            def tick(self) -> Status:
                return Status.SUCCESS
        """))
    _installed(tmp_path, monkeypatch, "clashing_nodes",
               "[cyborg.nodes]\nclashing = clashing_nodes\n")
    reg = default_registry(entry_points=False)
    problems = [problem for problem in reg.load_entry_points() if "clashing" in problem]
    assert len(problems) == 1
    assert "NameTakenError: node name 'Wait' is taken by cyborg.bt.leaves.Wait (from stock); " \
           "clashing_nodes.Wait (from clashing_nodes) would replace it" in problems[0]
    assert reg.get("Wait").cls.__module__ == "cyborg.bt.leaves"  # type: ignore[union-attr]
    monkeypatch.delitem(sys.modules, "clashing_nodes", raising=False)


def test_a_service_name_taken_is_refused_too() -> None:
    from cyborg.bt import Service
    from cyborg.bt.named_registry import NameTakenError
    from cyborg.bt.service_registry import ServiceRegistry
    from cyborg.bt.services import ServiceBoard

    class Watch(Service):
        def run(self, blackboard: ServiceBoard) -> None: ...

    class OtherWatch(Service):
        def run(self, blackboard: ServiceBoard) -> None: ...

    services = ServiceRegistry()
    services.add(Watch, "Watch")
    with pytest.raises(NameTakenError, match=r"service name 'Watch' is taken by .*Watch"):
        services.add(OtherWatch, "Watch")
    assert services.add(OtherWatch, "Watch", override=True).cls is OtherWatch
