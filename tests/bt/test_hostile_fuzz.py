"""Hostile tree files fuzzed (issue 19, items 8 and 10): never a crash, never a hang.

A hypothesis fuzz suite over tree files of both formats (150 examples each, about 5 s in all):
every input loads, and then ticks, halts, draws and serialises, or raises TreeLoadError whose
problems are all located; never another exception, never a hang; and no node's error while
ticking is logged as a traceback. Among the inputs are what real editor files hold: a loop
count of ``1e999`` (infinity: forever), ``"input": [null]`` (an unbound port), a Cmp without a
comparison, a Wait whose ``time`` is not a number of seconds. The attacks one by one are in the
other tests/bt/test_hostile_*.py modules.
"""

from __future__ import annotations

import itertools
import json
import logging
import os
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from cyborg.bt import ManualClock, Status, Tree, TreeLoadError, check_file, load_tree, loads_tree
from cyborg.bt import limits as bt_limits
from tests.bt.hostile_helpers import _bounded, _chain, _registry, assert_located

# Tree files of both formats, built from hostile parts: wrong types, NaN and infinities, huge
# and long numbers, lone surrogates, deep values, deep chains, references between trees and
# files (a FIFO among them), then sometimes cut or spliced as text. Every input must load (and
# then tick, halt, draw and serialise) or raise TreeLoadError whose problems are all located.
# Placeholders stand for what json.dumps cannot write (or would recurse on); _expand fills them.
_SPLICES = {"@@NAN@@": "NaN", "@@INF@@": "-Infinity", "@@E400@@": "1e400", "@@E999@@": "1e999",
            "@@DIGITS@@": "9" * 1200, "@@SURROGATE@@": '"a\\udc00"'}
_DECLARATIONS = ["BatteryWatch(interval=0.01, run_on_activation=true); ClosestGoal",
                 "BatteryWatch(interval=1e-300)", "Nope(", "ClosestGoal; ClosestGoal",
                 "BatteryWatch(interval=nan)", "BatteryWatch(key='\udc00')", "x" * 300 + "("]
"""Values of a composite's ``services`` property, good and bad (docs/services.md)."""
_SCALARS = st.one_of(
    st.none(), st.booleans(), st.integers(-(2 ** 70), 2 ** 70),
    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=6),
    st.sampled_from([10 ** 400, -(10 ** 400), -1, 0, 1, 2.5, "nan", "inf", "-Infinity",
                     "1e400", "9" * 400, "\ud800", "x\udfffy", *_SPLICES, *_DECLARATIONS]))
_VALUES = st.recursive(_SCALARS, lambda inner: st.lists(inner, max_size=3)
                       | st.dictionaries(st.text(max_size=4), inner, max_size=3), max_leaves=6)
_DEEP = st.integers(0, 1300).map(lambda n: f"@@DEEP{n}@@")
_PROPERTY = st.sampled_from(["milliseconds", "maxLoop", "maxTime", "maxAttempts", "below",
                             "radius", "count", "successThreshold", "location", "time",
                             "value", "expr", "x", "services"])
_PROPERTIES = st.dictionaries(_PROPERTY, _VALUES | _DEEP, max_size=3)
_TEXT = st.text(max_size=6) | st.sampled_from(["a\ud800", "<x> \udbff", "\U0001f916",
                                               "<value> <milliseconds>", "<expr><time>"])
_IDS = ["a", "b", "c", "d", "e"]
_TREES = ["t0", "t1", "t2"]
_NAMES = ["Sequence", "Priority", "MemSequence", "Parallel", "Inverter", "Repeater", "Wait",
          "Succeeder", "Failer", "Runner", "Timeout", "Limiter", "Retry", "MaxTime", "Below",
          *_TREES, "", "NoSuchNode"]
_V1_NAMES = ["Sequence", "Selector", "Parallel", "Invert", "AlwaysSuccess", "Wait", "Timeout",
             "JustSuccess", "JustFailure", "Check", "Let", "IfElse", "Once", "Repeat",
             "RetryUntilSuccess", "Race", "Delay", "Listen", "Cmp", "Nope", ""]


def _expand(text: str) -> str:
    """Fill the placeholders _SPLICES and _DEEP left in JSON text."""
    for marker, fragment in _SPLICES.items():
        text = text.replace(f'"{marker}"', fragment)
    while (start := text.find('"@@DEEP')) >= 0:
        end = text.index('@@"', start + 7)
        levels = int(text[start + 7:end])
        text = text[:start] + "[" * levels + "1" + "]" * levels + text[end + 3:]
    return text


@st.composite
def _node03(draw: st.DrawFn, node_id: str) -> dict[str, Any]:
    node: dict[str, Any] = {"id": draw(st.sampled_from([node_id] * 4 + [7, "other"]) | _DEEP),
                            "name": draw(st.sampled_from(_NAMES)), "title": draw(_TEXT),
                            "properties": draw(_PROPERTIES)}
    if draw(st.integers(0, 3)) == 0:  # the older name of properties
        node["parameters"] = draw(_PROPERTIES | _SCALARS)
    link = draw(st.sampled_from(["leaf", "child", "children", "bad"]))
    if link == "child":
        node["child"] = draw(st.sampled_from([*_IDS, "zz"]))
    elif link == "children":
        node["children"] = draw(st.lists(st.sampled_from([*_IDS, "zz"]), max_size=3))
    elif link == "bad":
        node[draw(st.sampled_from(["child", "children"]))] = draw(_SCALARS)
    return node


@st.composite
def _tree03(draw: st.DrawFn, tree_id: str) -> Any:
    ids = draw(st.lists(st.sampled_from(_IDS), min_size=1, max_size=5, unique=True))
    nodes = {node_id: draw(_node03(node_id)) for node_id in ids}
    root = draw(st.sampled_from([*ids, None, "zz"]))
    chain = draw(st.sampled_from([0, 0, 0, bt_limits.MAX_DEPTH - 3, bt_limits.MAX_DEPTH,
                                  1100]))
    if chain:  # a chain of decorators above the tree's own root
        nodes.update(_chain(chain, leaf=draw(st.sampled_from(_NAMES)))["nodes"])
        nodes[f"n{chain}"] = {"id": f"n{chain}", "name": "Inverter", "child": root}
        root = "n0"
    tree = {"id": draw(st.sampled_from([tree_id] * 5) | _DEEP), "title": draw(_TEXT),
            "root": root, "nodes": nodes, "properties": draw(_PROPERTIES)}
    return tree if draw(st.integers(0, 9)) else draw(_VALUES)


_NUMBER = st.integers(0, 9).flatmap(
    lambda k: _SCALARS if k == 0 else st.integers(1, 5) if k < 8 else st.floats(0, 2000))
_TAME_LEAVES = {"Succeeder": {}, "Failer": {}, "Runner": {}, "Wait": {"milliseconds": _NUMBER},
                "Below": {"below": _NUMBER, "radius": _NUMBER, "count": _NUMBER}}
_LOOPS = _NUMBER | st.just("@@E999@@")
"""A loop count: mostly a plausible number, sometimes infinity as JSON writes it (1e999)."""
_TAME_DECORATORS = {"Inverter": {}, "Repeater": {"maxLoop": _LOOPS},
                    "Timeout": {"milliseconds": _NUMBER}, "Limiter": {"maxLoop": _LOOPS},
                    "Retry": {"maxAttempts": _LOOPS}, "MaxTime": {"maxTime": _NUMBER}}


@st.composite
def _tame_node03(draw: st.DrawFn, node_id: str, choices: dict[str, dict[str, Any]],
                 ) -> dict[str, Any]:
    name = draw(st.sampled_from(sorted(choices)))
    properties = {key: draw(value) for key, value in choices[name].items()
                  if draw(st.integers(0, 5))}
    return {"id": node_id, "name": name, "title": draw(st.text(max_size=8)),
            "properties": properties}


@st.composite
def _tame_tree03(draw: st.DrawFn, tree_id: str, later: list[str]) -> dict[str, Any]:
    """A tree the engine should mostly accept: a composite over leaves (or references to the
    ``later`` trees), each maybe wrapped in a decorator, with plausible (sometimes hostile)
    numbers, maybe under a long chain."""
    leaves = {**_TAME_LEAVES, **{name: {} for name in later}}
    children: list[str] = []
    nodes: dict[str, Any] = {"root": {"id": "root", "name": draw(st.sampled_from(
        ["Sequence", "Priority", "MemSequence", "MemPriority", "Parallel"])),
        "children": children}}
    for index in range(draw(st.integers(1, 4))):
        leaf = draw(_tame_node03(f"l{index}", leaves))
        nodes[leaf["id"]] = leaf
        top = leaf["id"]
        if draw(st.booleans()):
            decorator = draw(_tame_node03(f"d{index}", _TAME_DECORATORS))
            decorator["child"] = leaf["id"]
            nodes[decorator["id"]] = decorator
            top = decorator["id"]
        children.append(top)
    root = "root"
    chain = draw(st.sampled_from([0, 0, 0, 0, 5, bt_limits.MAX_DEPTH - 9,
                                  bt_limits.MAX_DEPTH]))
    if chain:
        nodes.update(_chain(chain)["nodes"])
        nodes[f"n{chain}"] = {"id": f"n{chain}", "name": "Inverter", "child": root}
        root = "n0"
    return {"id": tree_id, "title": draw(st.text(max_size=6)), "root": root, "nodes": nodes}


@st.composite
def _file03(draw: st.DrawFn) -> str:
    count = draw(st.integers(1, 3))
    if draw(st.booleans()):  # tame: a project the engine should mostly load
        tame = [draw(_tame_tree03(tree_id, _TREES[index + 1:count]))
                for index, tree_id in enumerate(_TREES[:count])]
        return _expand(json.dumps({"trees": tame, "selectedTree": "t0"}, indent=1))
    trees: list[Any] = [draw(st.one_of(_tame_tree03(tree_id, _TREES), _tree03(tree_id)))
             for tree_id in _TREES[:count]]
    shape = draw(st.sampled_from(["project", "project", "tree", "desktop", "nodes"]))
    data: Any
    if shape == "tree" and isinstance(trees[0], dict):
        data = {"scope": "tree", **trees[0]}
    elif shape == "nodes":
        data = draw(st.lists(st.fixed_dictionaries({"name": _TEXT, "category": _TEXT}),
                             max_size=3))
    else:
        data = {"trees": trees, "selectedTree": draw(st.sampled_from([*_TREES, None, 5])),
                "custom_nodes": draw(st.lists(_VALUES | _DEEP, max_size=2))}
        data = {"name": "p", "data": data} if shape == "desktop" else data
    return _mutate(draw, _expand(json.dumps(data, indent=draw(st.sampled_from([None, 1])))))


def _mutate(draw: st.DrawFn, text: str) -> str:
    """Sometimes cut, splice into or repeat part of ``text``."""
    how = draw(st.sampled_from(["none"] * 6 + ["cut", "insert", "drop"]))
    if how == "none" or not text:
        return text
    at = draw(st.integers(0, len(text) - 1))
    if how == "cut":
        return text[:at]
    if how == "insert":
        return text[:at] + draw(st.sampled_from(['"', "{", "]", ",", "\\ud800", "9" * 1100,
                                                  "\x00", "\ufeff"])) + text[at:]
    return text[:at] + text[at + draw(st.integers(1, 20)):]


@st.composite
def _node_v1(draw: st.DrawFn, depth: int = 0) -> dict[str, Any]:
    node: dict[str, Any] = {
        "id": draw(st.one_of(st.integers(-3, 40), st.text(max_size=3), _DEEP,
                             st.sampled_from([None, True, 10 ** 400]))),
        "name": draw(st.sampled_from(_V1_NAMES)), "desc": draw(_TEXT)}
    for key, strategy in (("args", _PROPERTIES | _SCALARS),
                          ("input", st.lists(st.sampled_from(["a", "b", "", None]), max_size=2)
                           | _SCALARS),
                          ("output", st.lists(st.sampled_from(["a", "c"]), max_size=2)),
                          ("disabled", st.booleans()),
                          ("path", st.sampled_from(["sub.json", "fifo.json", "missing.json",
                                                    "main.json", "deep.json", "", 5]))):
        if draw(st.integers(0, 3)) == 0:
            node[key] = draw(strategy)
    if depth < 3 and draw(st.booleans()):
        node["children"] = [draw(_node_v1(depth + 1)) for _ in range(draw(st.integers(0, 3)))]
    return node


_TAME_V1 = {"JustSuccess": {}, "JustFailure": {}, "Wait": {"time": _NUMBER},
            "Check": {"value": st.sampled_from(["a > 1", "b", "c.d[0] + 'x'", "1 / 0"])},
            "Let": {"value": _VALUES}, "Sequence": {}, "Selector": {}, "Parallel": {},
            "Invert": {}, "AlwaysSuccess": {}, "Once": {}, "Repeat": {"count": _LOOPS},
            "Timeout": {"time": _NUMBER}, "Race": {}, "IfElse": {},
            "Cmp": {"gt": _NUMBER, "lt": _NUMBER}}


@st.composite
def _tame_v1(draw: st.DrawFn, depth: int = 0, subtree: bool = True) -> dict[str, Any]:
    """A v1 node the engine should mostly accept (ids made unique when the file is written);
    ``subtree``: it may reference ``sub.json``."""
    leaf = depth >= 3
    name = draw(st.sampled_from(sorted(k for k in _TAME_V1 if not leaf or not _ARITY.get(k))))
    node: dict[str, Any] = {"id": 0, "name": name, "args": {
        key: draw(value) for key, value in _TAME_V1[name].items() if draw(st.integers(0, 5))}}
    if name in ("Check", "Cmp") and draw(st.booleans()):
        node["input"] = [draw(st.sampled_from(["a", None]))]
    if name == "Let":
        node["output"] = ["a"]
    low, high = _ARITY.get(name, (0, 0))
    if high:
        node["children"] = [draw(_tame_v1(depth + 1, subtree))
                            for _ in range(draw(st.integers(low, high)))]
    elif subtree and draw(st.integers(0, 5)) == 0:
        node = {"id": 0, "name": "Sequence", "path": "sub.json"}
    return node


_ARITY = {"Sequence": (1, 3), "Selector": (1, 3), "Parallel": (1, 3), "Race": (1, 3),
          "IfElse": (2, 3), "Invert": (1, 1), "AlwaysSuccess": (1, 1), "Once": (1, 1),
          "Repeat": (1, 1), "Timeout": (1, 1)}


def _numbered(node: dict[str, Any], ids: Iterator[int]) -> dict[str, Any]:
    """``node`` with fresh ids given depth first (its children lists are shallow)."""
    pending = [node]
    while pending:
        item = pending.pop()
        item["id"] = next(ids)
        pending.extend(child for child in item.get("children", []) if isinstance(child, dict))
    return node


@st.composite
def _files_v1(draw: st.DrawFn) -> dict[str, str]:
    """File name -> text (``None`` text: make a FIFO) of a v1 workdir; ``main.json`` is run."""
    tame = draw(st.booleans())  # files the engine should mostly load

    def tree_text(subtree: bool = True) -> str:
        if tame:
            return _expand(json.dumps({"name": "t", "root": _numbered(
                draw(_tame_v1(0, subtree)), itertools.count(1))}))
        root = draw(st.one_of(_tame_v1().map(lambda n: _numbered(n, itertools.count(1))),
                              _node_v1()))
        data = {"name": draw(_TEXT), "root": root,
                **draw(st.dictionaries(st.sampled_from(["vars", "import", "version"]),
                                       _VALUES | st.just(["vars.json"]), max_size=2))}
        return _mutate(draw, _expand(json.dumps(data)))

    levels = draw(st.sampled_from([1, 10, bt_limits.MAX_DEPTH, 1200]))
    deep = "".join(f'{{"id": {i}, "name": "Invert", "children": [' for i in range(levels))
    files = {"main.json": tree_text(), "sub.json": tree_text(subtree=False),
             "deep.json": '{"root": ' + deep + '{"id": "x", "name": "Wait"}' + "]}" * levels
             + "}",
             "vars.json": _expand(json.dumps({"vars": draw(_VALUES), "import": ["vars.json"]}))}
    if draw(st.booleans()):
        files["node-config.b3-setting"] = _expand(json.dumps(draw(st.lists(
            st.fixed_dictionaries({"name": st.sampled_from(_V1_NAMES), "type": _TEXT,
                                   "args": _VALUES}), max_size=3))))
    return files


class _Tracebacks(logging.Handler):
    """Collects the records of ``cyborg.bt`` that carry a traceback."""

    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        if record.exc_info:
            self.records.append(record)


def _exercise(load: Callable[[], Tree]) -> str:
    """Load; on success tick, draw, serialise and halt the tree; on failure check the
    problems are located. Returns what happened, for hypothesis' statistics. No node's error
    while ticking is a traceback: the stock nodes report bad input as a NodeError, one line."""
    try:
        tree = load()
    except TreeLoadError as exc:
        assert exc.problems
        for problem in exc.problems:
            assert_located(problem)
        str(exc).encode("utf-8")
        return "refused"
    tracebacks = _Tracebacks()
    logger = logging.getLogger("cyborg.bt")
    logger.addHandler(tracebacks)
    try:
        for _ in range(3):
            tree.tick()
            assert isinstance(tree.clock, ManualClock)
            tree.clock.advance(0.5)
    finally:
        logger.removeHandler(tracebacks)
    assert not tracebacks.records, [record.getMessage() for record in tracebacks.records]
    tree.to_dot().encode("utf-8")
    json.dumps(tree.structure.to_json(), ensure_ascii=False).encode("utf-8")
    tree.halt()
    return "loaded"


_FUZZ = settings(max_examples=150, deadline=5000,
                 suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


@_FUZZ
@given(text=_file03(), stub=st.sampled_from([None, Status.SUCCESS, Status.RUNNING]),
       max_nodes=st.sampled_from([None, 40]))
def test_fuzz_behavior3editor_files(text: str, stub: Status | None,
                                    max_nodes: int | None) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "tree.b3.json"
        path.write_text(text, encoding="utf-8", errors="surrogatepass")
        registry = _registry()
        event(str(_bounded(lambda: _exercise(lambda: load_tree(
            path, registry=registry, clock=ManualClock(), stub_missing=stub,
            max_nodes=max_nodes)))))
        _bounded(lambda: _exercise(lambda: loads_tree(
            text, registry=registry, clock=ManualClock(), stub_missing=stub)))
        problems = _bounded(lambda: check_file(path, registry=registry, stub_missing=stub))
        assert isinstance(problems, list)
        for problem in problems:
            assert_located(problem)


@_FUZZ
@given(files=_files_v1(), fifo=st.booleans(), stub=st.sampled_from([None, Status.SUCCESS]))
def test_fuzz_behavior3_v1_workdirs(files: dict[str, str], fifo: bool,
                                    stub: Status | None) -> None:
    with tempfile.TemporaryDirectory() as folder:
        workdir = Path(folder)
        (workdir / "robot.b3-workspace").write_text("{}")
        for name, text in files.items():
            (workdir / name).write_text(text, encoding="utf-8", errors="surrogatepass")
        if fifo and hasattr(os, "mkfifo"):
            os.mkfifo(workdir / "fifo.json")
        main = workdir / "main.json"
        event(str(_bounded(lambda: _exercise(lambda: load_tree(main, clock=ManualClock(),
                                                               stub_missing=stub)))))
        problems = _bounded(lambda: check_file(main, stub_missing=stub))
        assert isinstance(problems, list)
        for problem in problems:
            assert_located(problem)
