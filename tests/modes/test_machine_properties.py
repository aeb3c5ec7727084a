"""Property tests: random valid mode machines under random blackboard values, events, requests.

Each machine has 2-5 modes, each running its own tree of Scripted actions under composites;
every mode is reachable (a chain of transitions from the initial mode, with random triggers)
and random extra transitions, dwell times and time limits are added. Random steps then move
the clock, tick, write the global blackboard, publish events, request, force and hold modes.
After every step:

(a) the machine is in exactly one declared mode, and the trees of all other modes have no
    RUNNING node and no Scripted activation left open;
(b) at each transition (seen by a listener, after the switch) the left tree has no RUNNING node
    and every activation of its Scripted nodes was closed by exactly one end or halt;
(c) the transition log is a chain from the initial mode to the current one, in time order;
    nothing but a force left a held mode, and no condition, event or request left a mode before
    its dwell time was over.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cyborg.bt import RUNNING, Blackboard, ManualClock
from cyborg.modes import ModeMachine, Transition, Trigger, build_machine, parse_mode_file
from tests.builders import N, project_json, registry, tree_json

TREES = {
    "t0": N("Sequence", N("Scripted", script="RRS", tag="t0a"),
            N("Scripted", script="R", tag="t0b")),
    "t1": N("Priority", N("Scripted", script="FR", tag="t1a"),
            N("Scripted", script="RS", tag="t1b")),
    "t2": N("Parallel", N("Scripted", script="R", tag="t2a"),
            N("Scripted", script="SRRF", tag="t2b"), policy="all"),
    "t3": N("Scripted", script="RRRE", tag="t3a"),
    "t4": N("MemSequence", N("Scripted", script="RS", tag="t4a"),
            N("Scripted", script="RRRRS", tag="t4b")),
}
VARIABLES = ("x", "y")
EVENTS = ("e0", "e1", "e2")


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("modes")
    trees = [tree_json(spec, tree_id=name, title=name) for name, spec in TREES.items()]
    (path / "mission.b3.json").write_text(project_json(trees))
    return path


@st.composite
def mode_files(draw: st.DrawFn) -> str:
    count = draw(st.integers(2, 5))
    modes = [f"m{i}" for i in range(count)]
    lines = ['project = "mission.b3.json"', 'initial = "m0"',
             f"min_dwell = {draw(st.sampled_from([0.0, 0.5, 1.0]))}"]
    for index, mode in enumerate(modes):
        lines += [f"[modes.{mode}]", f'tree = "t{index}"']
        if draw(st.booleans()):
            lines.append(f"min_dwell = {draw(st.sampled_from([0.0, 0.3, 2.0]))}")
        if draw(st.integers(0, 3)) == 0:
            then = draw(st.sampled_from([m for m in modes if m != mode]))
            lines += [f"max_time = {draw(st.sampled_from([0.5, 1.0, 3.0]))}", f'then = "{then}"']
    pairs = [(modes[i - 1], modes[i]) for i in range(1, count)]
    pairs += draw(st.lists(st.tuples(st.sampled_from([*modes, "*"]), st.sampled_from(modes)),
                           max_size=6))
    seen = set()
    for source, target in pairs:
        trigger = draw(st.sampled_from(["when", "event", "on_request"]))
        if trigger == "when":
            value = f'when = "{draw(st.sampled_from(VARIABLES))} == {draw(st.integers(0, 2))}"'
        elif trigger == "event":
            value = f'event = "{draw(st.sampled_from(EVENTS))}"'
        else:
            value = "on_request = true"
        key = (source, target, value)
        if source == target or key in seen:
            continue
        seen.add(key)
        lines += ["[[transitions]]", f'from = "{source}"', f'to = "{target}"', value]
        if draw(st.integers(0, 3)) == 0:
            lines.append(f'guard = "{draw(st.sampled_from(VARIABLES))} != 1"')
    return "\n".join(lines) + "\n"


STEPS = st.one_of(
    st.tuples(st.just("tick"), st.sampled_from([0.0, 0.1, 0.4, 1.5])),
    st.tuples(st.just("set"), st.sampled_from(VARIABLES), st.integers(0, 2)),
    st.tuples(st.just("event"), st.sampled_from(EVENTS)),
    st.tuples(st.just("request"), st.sampled_from(["m0", "m1", "m2", "m3", "m4"])),
    st.tuples(st.just("force"), st.sampled_from(["m0", "m1", "m2", "m3", "m4"])),
    st.tuples(st.just("hold"), st.booleans()),
)


def open_activations(log: list[tuple[str, str]], tags: set[str]) -> dict[str, int]:
    """Per Scripted tag, activations started and not closed; fails on a double close."""
    open_: dict[str, int] = dict.fromkeys(tags, 0)
    for event, tag in log:
        if tag not in tags:
            continue
        if event == "start":
            assert open_[tag] == 0, f"{tag} started twice"
            open_[tag] = 1
        elif event == "halt" or event.startswith("end:"):
            assert open_[tag] == 1, f"{tag} closed twice ({event})"
            open_[tag] = 0
    return open_


def tags_of(m: ModeMachine, mode: str) -> set[str]:
    return {node.tag for node in m.trees[mode].nodes if hasattr(node, "tag")}


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(text=mode_files(), steps=st.lists(STEPS, min_size=10, max_size=60))
def test_random_machines_keep_their_invariants(folder: Path, text: str,
                                               steps: list[tuple[Any, ...]]) -> None:
    clock = ManualClock()
    spec = parse_mode_file(text, "random.modes.toml", folder)
    m = build_machine(spec, registry=registry(), clock=clock,
                      blackboard=Blackboard({"events": []}))
    log: list[tuple[str, str]] = m.globals["events"]
    held = False
    seen: list[tuple[Transition, bool]] = []

    def on_transition(transition: Transition) -> None:
        left = m.trees[transition.source]
        assert not [node for node in left.nodes if node.status is RUNNING]
        assert set(open_activations(log, tags_of(m, transition.source)).values()) <= {0}
        seen.append((transition, held))

    m.add_listener(on_transition)
    m.tick()  # the machine starts at 0
    for step in steps:
        kind = step[0]
        if kind == "tick":
            clock.advance(step[1])
            m.tick()
        elif kind == "set":
            m.globals[step[1]] = step[2]
        elif kind == "event":
            m.fire_event(step[1])
        elif kind == "request":
            m.request(step[1])
        elif kind == "force":
            m.force(step[1])
        else:
            held = step[1]
            m.hold(held)
        assert m.mode in spec.modes
        for mode in spec.modes:
            if mode != m.mode:
                assert not [node for node in m.trees[mode].nodes if node.status is RUNNING]
                assert set(open_activations(log, tags_of(m, mode)).values()) <= {0}
    current, since = spec.initial, 0.0
    assert [t for t, _ in seen] == list(m.history)
    for transition, was_held in seen:
        assert transition.source == current and transition.target != current
        assert transition.time >= since
        if was_held:
            assert transition.trigger is Trigger.FORCE
        if transition.trigger in (Trigger.CONDITION, Trigger.EVENT, Trigger.REQUEST):
            assert transition.time - since >= spec.modes[current].min_dwell
        current, since = transition.target, transition.time
    assert current == m.mode
