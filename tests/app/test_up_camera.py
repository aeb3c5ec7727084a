"""`cyborg up --camera`: the simulator's camera by default, the real detector on sample frames
with `real` or on any other source, the same detector topics either way; `--people N`."""

from __future__ import annotations

from pathlib import Path

import pytest

from cyborg.app import up_vision
from cyborg.app.cli import build_parser
from cyborg.app.errors import CommandError
from cyborg.app.up import DEFAULT_PEOPLE, up_description
from cyborg.bus.component import NodeSpec
from cyborg.interfaces.detector import detector_of_robot


def _specs(*words: str) -> dict[str, NodeSpec]:
    args = build_parser().parse_args(["up", "--no-monitor", *words])
    return {spec.kind: spec for spec in up_description(args).nodes}


@pytest.fixture(autouse=True)
def _model(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(up_vision, "model_for_up", lambda name: Path(f"/models/{name}.onnx"))


def test_by_default_the_simulator_sees_through_its_own_camera_and_people_walk() -> None:
    specs = _specs()
    simulator = specs["simulator"]
    assert simulator.parameters["camera"] is True
    assert simulator.parameters["people"] == DEFAULT_PEOPLE > 0
    assert "camera" not in specs and "detector" not in specs, "no frames, no model"


def test_real_swaps_in_the_detector_on_sample_frames_on_the_same_topics() -> None:
    specs = _specs("--camera", "real")
    assert specs["simulator"].parameters["camera"] is False
    assert specs["camera"].parameters["source"] == up_vision.CAMERA_SOURCE
    simulator = specs["simulator"]
    assert specs["detector"].namespace == detector_of_robot(simulator.namespace), (
        "where the simulated camera publishes: the tree reads the same topics")


def test_any_other_source_feeds_the_real_detector(tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    specs = _specs("--camera", "ride.mp4")
    assert specs["simulator"].parameters["camera"] is False
    assert specs["camera"].parameters["source"] == str(tmp_path / "ride.mp4")


def test_no_detector_means_no_camera_of_either_kind() -> None:
    specs = _specs("--no-detector")
    assert specs["simulator"].parameters["camera"] is False
    assert "camera" not in specs and "detector" not in specs


def test_people_can_be_chosen_but_not_fewer_than_none() -> None:
    assert _specs("--people", "0")["simulator"].parameters["people"] == 0
    assert _specs("--people", "10")["simulator"].parameters["people"] == 10
    with pytest.raises(CommandError, match="--people must be 0 or more, not -2"):
        _specs("--people", "-2")
