"""Finding model files, and fetching known ones with their checksum verified.

A model is given by path, or by name (``yolox_nano``) and then looked for, in order, in the
folder named by ``CYBORG_MODELS``, in the project's shared data (``$CYBORG_SHARED/models``, by
default ``../shared/models`` beside a source checkout), and in the user's cache
(``~/.cache/cyborg/models``, or ``$XDG_CACHE_HOME/cyborg/models``).

``cyborg detect models fetch yolox_nano`` downloads a known model into the cache (or
``--dir``), checks its SHA-256 against the catalogue and only then moves it into place, so a
failed or tampered download never leaves a file behind.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
import urllib.error
import urllib.request
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from cyborg.vision.frames import VisionError

DEFAULT_MODEL = "yolox_nano"


@dataclass(frozen=True)
class KnownModel:
    """A model that can be fetched by name: where from, its SHA-256 and size (bytes), licence."""

    name: str
    url: str
    sha256: str
    size: int
    family: str
    licence: str
    description: str

    @property
    def filename(self) -> str:
        """The file it is saved as in a models folder."""
        return f"{self.name}.onnx"


CATALOGUE = {model.name: model for model in (
    KnownModel("yolox_nano",
               "https://github.com/Megvii-BaseDetection/YOLOX/releases/download/0.1.1rc0/"
               "yolox_nano.onnx",
               "c789161ed43c8269fcd4e67c67eeeb4e80c622da2eb296a20bc6007bd18a0b7d", 3_659_407,
               "yolox", "Apache-2.0",
               "YOLOX-Nano, COCO 80 classes, 416x416 input, 0.91 M parameters"),
)}
"""Models ``cyborg detect models fetch`` knows, with where they come from and their hash."""


def model_dirs() -> list[Path]:
    """Folders searched for models by name, in order."""
    dirs = []
    if os.environ.get("CYBORG_MODELS"):
        dirs.append(Path(os.environ["CYBORG_MODELS"]).expanduser())
    shared = os.environ.get("CYBORG_SHARED")
    if shared:
        dirs.append(Path(shared).expanduser() / "models")
    else:
        beside_checkout = Path(__file__).resolve().parents[3].parent / "shared" / "models"
        if beside_checkout.is_dir():  # src/cyborg/vision/models.py → <checkout>/../shared
            dirs.append(beside_checkout)
    dirs.append(cache_dir())
    return dirs


def cache_dir() -> Path:
    """The user's model cache, where fetched models go: ``$XDG_CACHE_HOME/cyborg/models``."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "cyborg" / "models"


def find_model(name_or_path: str | os.PathLike[str]) -> Path:
    """The model file for a path or a model name; a clear error saying where it looked.

    The one resolver of the project: ``cyborg detect --model``, ``cyborg up --model``, the
    detector launch kind and :meth:`Detector.open <cyborg.vision.detector.Detector.open>` all
    go through it, so a model found by one is found by all. A :class:`~pathlib.Path`, or a
    string ending in ``.onnx``/``.cfg`` or holding a ``/``, is a file (relative to the working
    folder); any other string is a name looked for in :func:`model_dirs`::

        find_model("yolox_nano")            # $CYBORG_MODELS, shared models/, the cache
        find_model("exports/best.onnx")     # that file
    """
    text = os.fspath(name_or_path)
    path = Path(text).expanduser()
    if not isinstance(name_or_path, str) or path.suffix in (".onnx", ".cfg") or "/" in text:
        if not path.is_file():
            raise VisionError(f"model file {path}: not found")
        return path
    name = text
    searched = model_dirs()
    for folder in searched:
        for candidate in (folder / f"{name}.onnx", folder / name):
            if candidate.is_file():
                return candidate
    hint = (f"; fetch it with `cyborg detect models fetch {name}`"
            if name in CATALOGUE else
            f"; known models: {', '.join(CATALOGUE)}, or give a path to an .onnx file")
    raise VisionError(f"model {name!r} not found in "
                      f"{', '.join(str(folder) for folder in searched)}{hint}")


def fetch(model: KnownModel, folder: Path | None = None, *, url: str | None = None,
          progress: Callable[[int, int], None] | None = None, timeout: float = 60.0) -> Path:
    """Download ``model`` into ``folder`` (default: the cache), verified by its SHA-256."""
    folder = folder or cache_dir()
    target = folder / model.filename
    if target.is_file() and _sha256(target) == model.sha256:
        return target
    folder.mkdir(parents=True, exist_ok=True)
    source = url or model.url
    digest = hashlib.sha256()
    handle, temporary = tempfile.mkstemp(prefix=f".{model.name}.", suffix=".part", dir=folder)
    try:
        with os.fdopen(handle, "wb") as out, urllib.request.urlopen(source,
                                                                    timeout=timeout) as reply:
            total = int(reply.headers.get("Content-Length") or model.size)
            done = 0
            while chunk := reply.read(1 << 16):
                out.write(chunk)
                digest.update(chunk)
                done += len(chunk)
                if progress is not None:
                    progress(done, total)
        if digest.hexdigest() != model.sha256:
            raise VisionError(f"{source}: SHA-256 {digest.hexdigest()} does not match the "
                              f"expected {model.sha256} for {model.name}; the file was not "
                              "kept")
        os.replace(temporary, target)
        return target
    except (urllib.error.URLError, OSError) as exc:
        reason = getattr(exc, "reason", None) or exc
        raise VisionError(f"cannot download {model.name} from {source}: {reason}") from exc
    finally:
        if os.path.exists(temporary):
            os.unlink(temporary)


def _sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with path.open("rb") as file:
        while chunk := file.read(1 << 20):
            digest.update(chunk)
    return digest.hexdigest()
