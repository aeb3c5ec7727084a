"""The Python examples of the vision docs run as written, and the library finds models the way
``cyborg detect --model`` does: a path, or a name in ``$CYBORG_MODELS``, the shared data's
``models/`` folder or the cache.

The examples are read from README.md (section "Object detection with distance") and
docs/vision.md and run in an empty working folder, so a hard-coded model path cannot pass.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from cyborg.vision import Detector, VisionError
from cyborg.vision.models import find_model
from tests.conftest import shared_dir

ROOT = Path(__file__).resolve().parents[2]
SECTION = "## Object detection with distance"


def python_blocks(markdown: str) -> list[str]:
    """The fenced ```python blocks of a Markdown text, in order."""
    return re.findall(r"^```python\n(.*?)^```$", markdown, flags=re.DOTALL | re.MULTILINE)


def readme_section(heading: str) -> str:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    start = text.index(heading)
    end = text.find("\n## ", start + len(heading))
    return text[start:] if end < 0 else text[start:end]


def run_example(code: str, where: str) -> None:
    exec(compile(code, where, "exec"), {"__name__": "__example__"})


@pytest.fixture
def elsewhere(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty working folder and an empty cache: only the model folders the variables name
    can hold the model."""
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.delenv("CYBORG_MODELS", raising=False)
    monkeypatch.delenv("CYBORG_SHARED", raising=False)
    return tmp_path


@pytest.mark.parametrize("variable", ["CYBORG_MODELS", "CYBORG_SHARED"])
def test_the_readme_vision_example_runs_as_written(
        variable: str, elsewhere: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    (code,) = python_blocks(readme_section(SECTION))
    folder = shared_dir() / "models" if variable == "CYBORG_MODELS" else shared_dir()
    monkeypatch.setenv(variable, str(folder))
    if variable == "CYBORG_MODELS":  # the shared data's default place must not be what finds it
        monkeypatch.setenv("CYBORG_SHARED", str(elsewhere / "no_shared"))
    run_example(code, "README.md")
    assert re.search(r"^motorcycle 0\.9\d at 2\.3\d m$", capsys.readouterr().out, re.MULTILINE)


def test_the_docs_pipeline_example_runs_as_written(elsewhere: Path,
                                                   monkeypatch: pytest.MonkeyPatch,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv("CYBORG_SHARED", str(shared_dir()))
    blocks = python_blocks((ROOT / "docs" / "vision.md").read_text(encoding="utf-8"))
    assert blocks, "docs/vision.md shows the pipeline in Python"
    run_example(blocks[0], "docs/vision.md")
    out = capsys.readouterr().out
    assert out.startswith("motorcycle 0.9") and "'inference'" in out


def test_detector_open_resolves_a_model_as_cyborg_detect_does(
        elsewhere: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CYBORG_MODELS", str(shared_dir() / "models"))
    model = shared_dir() / "models" / "yolox_nano.onnx"
    assert find_model("yolox_nano") == model
    by_name = Detector.open("yolox_nano", threads=1)
    assert by_name.model_name == "yolox_nano.onnx"
    assert Detector.open(str(model), threads=1).model_name == "yolox_nano.onnx"
    assert Detector.open(model, threads=1).model_name == "yolox_nano.onnx"
    with pytest.raises(VisionError, match=r"model file .*gone\.onnx: not found"):
        Detector.open("gone.onnx")
    with pytest.raises(VisionError, match=r"model 'mystery' not found in .*models.*known "
                                          r"models: yolox_nano"):
        Detector.open("mystery")
    with pytest.raises(VisionError, match=r"model file .*yolox_nano: not found"):
        Detector.open(Path("yolox_nano"))  # a Path is a file, never a name
