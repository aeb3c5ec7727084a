"""Writes constraints.txt: the versions pip would install today for ``.[dev]``, every one pinned.

``scripts/test.sh`` installs with ``-c constraints.txt``, so the tested set changes only when
this script is run on purpose (then run the tests, and commit the file with what they needed):

    python3 scripts/update_constraints.py
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HEADER = """\
# The exact versions `bash scripts/test.sh` installs and tests (pip install -c constraints.txt).
# pyproject.toml keeps the ranges the project allows; this file is what a fresh machine gets.
# Updated on purpose only: python3 scripts/update_constraints.py, then the tests.
"""


def resolved() -> list[tuple[str, str]]:
    """(name, version) of everything a fresh ``pip install -e .[dev]`` would take today."""
    with tempfile.TemporaryDirectory() as folder:
        report = Path(folder) / "report.json"
        subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--dry-run",
                        "--ignore-installed", "--report", str(report), "-e", ".[dev]"],
                       cwd=ROOT, check=True)
        installs = json.loads(report.read_text())["install"]
    return sorted((item["metadata"]["name"].lower(), item["metadata"]["version"])
                  for item in installs if item["metadata"]["name"].lower() != "cyborg")


def main() -> None:
    """Resolves and writes the file."""
    pins = resolved()
    (ROOT / "constraints.txt").write_text(
        HEADER + "".join(f"{name}=={version}\n" for name, version in pins))
    print(f"constraints.txt: {len(pins)} packages pinned")


if __name__ == "__main__":
    main()
