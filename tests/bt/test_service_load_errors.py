"""A bad services declaration is refused at load, naming file, line, node, column and names."""

from __future__ import annotations

import json
import sys
import textwrap
from pathlib import Path

import pytest

from cyborg.bt import (
    Problem,
    Service,
    ServiceBoard,
    ServiceRegistry,
    TreeLoadError,
    check_file,
    default_service_registry,
    load_tree,
    register_service,
)
from tests.bt.service_helpers import Probe, probe_registry
from tests.builders import N, project_json, registry, tree_json


class Needs(Service):
    """A service whose constructor checks its option."""

    def __init__(self, limit: int, label: str = "x") -> None:
        if limit < 0:
            raise ValueError("limit must be 0 or more")
        self.limit = limit

    def run(self, blackboard: ServiceBoard) -> None:
        blackboard["limit"] = self.limit


def _services() -> ServiceRegistry:
    services = probe_registry()
    services.add(Needs)
    return services


def _errors(tmp_path: Path, declaration: object, node: str = "Sequence") -> list[Problem]:
    spec = N(node, N("Runner"), id="patrol", title="Patrol loop", services=declaration) \
        if node != "Runner" else N("Sequence", N("Runner", id="patrol", title="Patrol loop",
                                                 services=declaration))
    path = tmp_path / "mission.b3.json"
    path.write_text(project_json([tree_json(spec)]))
    with pytest.raises(TreeLoadError) as caught:
        load_tree(path, registry=registry(), services=_services())
    return [problem for problem in caught.value.problems if problem.is_error]


@pytest.mark.parametrize(("declaration", "words"), [
    ("Prob(interval=1)", "column 1: unknown service 'Prob'; did you mean 'Probe'?"),
    ("Probe(period=1)", "column 7: Probe has no option 'period'; did you mean 'interval'?"),
    ("Probe(kee=a)", "column 7: Probe has no option 'kee'; did you mean 'key'?"),
    ("Probe(interval=fast)", "column 7: Probe: option 'interval': expected float"),
    ("Probe(interval=0)", "column 1: Probe: interval must be a number of seconds, at least"),
    ("Probe(interval=1e-300)", "column 1: Probe: interval must be a number of seconds, at"),
    ("Probe(interval=1e400)", "column 7: Probe: option 'interval': expected a finite number"),
    ("Probe(interval=1, deviation=1)", "deviation must be at least 0 and leave at least"),
    ("Probe(interval=1, deviation=-0.1)", "deviation must be at least 0 and leave at least"),
    ("Probe(run_on_activation=maybe)", "column 7: Probe: option 'run_on_activation'"),
    ("Probe(fail_after=x)", "column 7: Probe: option 'fail_after': expected int"),
    ("Needs", "column 1: Needs: missing option 'limit' (int)"),
    ("Needs(limit=-1)", "column 1: Needs(limit=-1) raised ValueError: limit must be 0"),
    ("Probe; Probe", "column 8: service 'Probe' is declared twice"),
    ("Probe(key=two words)", "column 11: 'two words' is not a value for option 'key'"),
    (["Probe"], 'the services property is text such as "BatteryWatch'),
])
def test_bad_declarations_name_file_line_node_and_column(tmp_path: Path, declaration: object,
                                                         words: str) -> None:
    (problem,) = _errors(tmp_path, declaration)
    text = str(problem)
    assert words in text
    assert text.startswith(f"{tmp_path / 'mission.b3.json'}:")
    assert problem.line is not None and problem.line > 1
    assert problem.node_id == "patrol" and problem.node_title == "Patrol loop"
    assert problem.field == "services"
    assert "node 'Patrol loop' (id patrol)" in text


def test_services_on_a_leaf_are_refused(tmp_path: Path) -> None:
    (problem,) = _errors(tmp_path, "Probe", node="Runner")
    assert "services attach to composites only" in problem.message
    assert "Runner is an action: move the property to the composite above it" in problem.message


def test_every_bad_service_of_a_file_is_reported_and_nothing_starts(tmp_path: Path) -> None:
    started: list[str] = []

    class Eager(Probe):
        def __init__(self) -> None:
            started.append("constructed")

    services = _services()
    services.add(Eager)
    spec = N("Sequence", N("Sequence", N("Runner"), services="Eager; Nope"),
             N("Priority", N("Runner"), services="Probe(period=2)"), services="Eager")
    path = tmp_path / "two.b3.json"
    path.write_text(project_json([tree_json(spec)]))
    problems = [p for p in check_file(path, registry=registry(), services=services)
                if p.is_error]
    assert len(problems) == 2
    assert {p.field for p in problems} == {"services"}
    with pytest.raises(TreeLoadError):
        load_tree(path, registry=registry(), services=services)
    assert "constructed" in started  # built to be checked, but never activated
    assert all(isinstance(p.line, int) for p in problems)


def test_unknown_service_lists_the_registered_ones(tmp_path: Path) -> None:
    (problem,) = _errors(tmp_path, "Zzz")
    assert "(registered: Needs, OtherProbe, Probe)" in problem.message


def test_the_decorator_and_entry_points_register_services(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "watch_services.py").write_text(textwrap.dedent("""
        from cyborg.bt import Service, register_service

        class Watch(Service):
            def run(self, blackboard):
                blackboard["watched"] = True

        @register_service("Glance")
        class Glance(Service):
            def run(self, blackboard):
                pass
        """))
    dist = tmp_path / "watch_services-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: watch-services\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text(
        "[cyborg.services]\nmodule = watch_services\nWatch = watch_services:Watch\n"
        "broken = watch_services_missing\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    services = ServiceRegistry()
    problems = services.load_entry_points()
    assert services.get("Glance") is not None
    watch = services.get("Watch")
    assert watch is not None and watch.origin == "entry point Watch"
    assert len(problems) == 1 and "broken" in problems[0]
    assert default_service_registry(entry_points=False).get("Glance") is not None
    monkeypatch.delitem(sys.modules, "watch_services")


def test_register_service_checks_what_it_registers() -> None:
    services = ServiceRegistry()
    with pytest.raises(TypeError, match="not a Service subclass"):
        services.add(int)
    with pytest.raises(ValueError, match="so a declaration can name it"):
        services.add(Probe, "Battery watch")

    @register_service
    class PlainNamed(Service):
        def run(self, blackboard: ServiceBoard) -> None:
            """Nothing to do."""

    assert default_service_registry(entry_points=False).get("PlainNamed") is not None


def test_a_service_without_run_is_reported_when_it_runs() -> None:
    class Lazy(Service):
        run_on_activation = True

    services = ServiceRegistry()
    services.add(Lazy)
    text = json.dumps(tree_json(N("Sequence", N("Runner"), services="Lazy")))
    from cyborg.bt import loads_tree
    tree = loads_tree(text, registry=registry(), services=services)
    snapshot = tree.tick()
    assert snapshot.services is not None
    assert snapshot.services[0].error == "NotImplementedError: Lazy does not implement run()"
