"""The stock nodes' properties checked at load: bad values and shapes are load errors.

A bad property (a threshold out of range, a loop count or time of zero, negative, fractional,
missing or not a number) is one load error that names the node and the property; a decorator
without a child or a leaf with one is a load error that names the node; values at the edge of
what is allowed load and work.
"""

from __future__ import annotations

import pytest

from cyborg.bt import FAILURE, RUNNING, SUCCESS, Status, TreeLoadError
from tests.bt.node_helpers import build, leaf
from tests.builders import N

LOAD_ERRORS: list[tuple[N, str, str]] = [
    # (spec whose root has id "bad", the property the message must name, a message fragment)
    (N("Parallel", leaf("a", "S"), leaf("b", "S"), id="bad", successThreshold=3),
     "successThreshold", "3"),
    (N("Parallel", leaf("a", "S"), leaf("b", "S"), id="bad", successThreshold=0),
     "successThreshold", "0"),
    (N("Parallel", leaf("a", "S"), leaf("b", "S"), id="bad", successThreshold=-2),
     "successThreshold", "-2"),
    (N("Parallel", leaf("a", "S"), leaf("b", "S"), id="bad", failureThreshold=0),
     "failureThreshold", "0"),
    (N("Parallel", leaf("a", "S"), leaf("b", "S"), id="bad", failureThreshold=5),
     "failureThreshold", "5"),
    (N("Parallel", leaf("a", "S"), id="bad", failureThreshold="x"), "failureThreshold", "x"),
    (N("Repeater", leaf("a", "S"), id="bad", maxLoop=0), "maxLoop", "0"),
    (N("Repeater", leaf("a", "S"), id="bad", maxLoop=-2), "maxLoop", "-2"),
    (N("Repeater", leaf("a", "S"), id="bad", maxLoop=1.5), "maxLoop", "1.5"),
    (N("RepeatUntilFailure", leaf("a", "S"), id="bad", maxLoop=0), "maxLoop", "0"),
    (N("RepeatUntilSuccess", leaf("a", "S"), id="bad", maxLoop=-3), "maxLoop", "-3"),
    (N("Retry", leaf("a", "S"), id="bad", maxAttempts=0), "maxAttempts", "0"),
    (N("Retry", leaf("a", "S"), id="bad", maxAttempts=-7), "maxAttempts", "-7"),
    (N("Limiter", leaf("a", "S"), id="bad", maxLoop=-1), "maxLoop", "-1"),
    (N("MaxTime", leaf("a", "S"), id="bad", maxTime=0), "maxTime", "0"),
    (N("MaxTime", leaf("a", "S"), id="bad", maxTime=-10), "maxTime", "-10"),
    (N("MaxTime", leaf("a", "S"), id="bad"), "maxTime", "missing"),
    (N("Timeout", leaf("a", "S"), id="bad", milliseconds=0), "milliseconds", "0"),
    (N("Timeout", leaf("a", "S"), id="bad", milliseconds=-1), "milliseconds", "-1"),
    (N("Timeout", leaf("a", "S"), id="bad"), "milliseconds", "missing"),
    (N("Delay", leaf("a", "S"), id="bad", milliseconds=-5), "milliseconds", "-5"),
    (N("Wait", id="bad", milliseconds=-1), "milliseconds", "-1"),
    (N("Wait", id="bad", milliseconds="soon"), "milliseconds", "soon"),
]


@pytest.mark.parametrize(
    ("spec", "prop", "fragment"),
    [pytest.param(spec, prop, fragment, id=f"{spec.name}-{prop}-{fragment}")
     for spec, prop, fragment in LOAD_ERRORS],
)
def test_bad_property_is_a_load_error(spec: N, prop: str, fragment: str) -> None:
    with pytest.raises(TreeLoadError) as caught:
        build(spec)
    message = str(caught.value)
    assert "(id bad)" in message
    assert prop in message
    assert fragment in message
    errors = [problem for problem in caught.value.problems if problem.is_error]
    assert len(errors) == 1
    assert errors[0].node_id == "bad"
    assert prop in errors[0].message or errors[0].field == prop


@pytest.mark.parametrize(
    "spec",
    [pytest.param(N("Inverter", id="bad"), id="no child"),
     pytest.param(N("Failer", leaf("a", "S"), id="bad"), id="leaf with a child")],
)
def test_bad_shape_is_a_load_error(spec: N) -> None:
    with pytest.raises(TreeLoadError) as caught:
        build(spec)
    assert "(id bad)" in str(caught.value)


@pytest.mark.parametrize(
    ("spec", "status"),
    [pytest.param(N("Parallel", leaf("a", "S"), leaf("b", "S"), successThreshold=2,
                    failureThreshold=2), SUCCESS, id="Parallel thresholds = children"),
     pytest.param(N("Repeater", leaf("a", "S"), maxLoop=1), SUCCESS, id="Repeater 1"),
     pytest.param(N("Limiter", leaf("a", "S"), maxLoop=0), FAILURE, id="Limiter 0"),
     pytest.param(N("Timeout", leaf("a", "S"), milliseconds=0.5), SUCCESS, id="Timeout 0.5"),
     pytest.param(N("Repeater", leaf("a", "S"), maxLoop="2"), RUNNING, id="number as text")],
)
def test_edge_property_values_load(spec: N, status: Status) -> None:
    assert build(spec).tick().status is status
