"""The benchmark commands of README.md and docs/*.md run as written.

Every benchmark is a module run as ``python3 -m benchmarks.NAME`` from the repository root (the
one way the documents write them); every command the documents give is checked against that
benchmark's own options, every benchmark has a documented quick variant, and the one command
that runs every quick variant, ``python3 -m benchmarks --quick``, is run as the documents write
it. Every ``cyborg`` command of a code block is one the command line takes: its words parse
(running them needs a robot; the README's ``cyborg bt`` commands are run in
tests/app/test_cli.py, from the same reading of the documents, tests/doc_commands.py).
"""

from __future__ import annotations

import contextlib
import importlib
import importlib.util
import io
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
from benchmarks import BENCHMARKS

from cyborg.app.cli import build_parser
from tests.doc_commands import ROOT, DocCommand, doc_commands

BENCHMARKS_DOC = ROOT / "docs" / "benchmarks.md"
RUN_ALL = "python3 -m benchmarks --quick"


def benchmark_commands() -> list[DocCommand]:
    """Every command of the documents that runs a benchmark, in either spelling."""
    return [command for command in doc_commands("python3")
            if (command.words[1:2] == ["-m"] and command.words[2].startswith("benchmarks"))
            or command.words[1].startswith("benchmarks/")]


def test_the_documents_run_benchmarks_as_modules_of_the_repository() -> None:
    commands = benchmark_commands()
    assert len(commands) >= 2 * len(BENCHMARKS), "a full run and a quick one each"
    as_paths = [f"{command.where}: {command.text}" for command in commands
                if command.words[1] != "-m"]
    assert not as_paths, ("run a benchmark as python3 -m benchmarks.NAME (as a path it cannot "
                          "import the benchmarks package):\n" + "\n".join(as_paths))


def test_every_documented_benchmark_command_is_one_its_benchmark_takes() -> None:
    refused = []
    for command in benchmark_commands():
        if command.words[1] != "-m":
            continue  # refused by the test above
        module = command.words[2]
        name = module.removeprefix("benchmarks").removeprefix(".")
        if name and name not in BENCHMARKS:
            refused.append(f"{command.where}: no benchmark {module}")
            continue
        try:  # python3 -m benchmarks runs benchmarks/__main__.py
            importlib.import_module(module if name else "benchmarks.__main__").parser() \
                .parse_args(command.words[3:])
        except SystemExit:
            refused.append(f"{command.where}: {command.text}: options refused (above)")
    assert not refused, "\n".join(refused)


def test_every_benchmark_is_listed_and_documented_with_a_quick_variant() -> None:
    runnable = {path.stem for path in (ROOT / "benchmarks").glob("*.py")
                if 'if __name__ == "__main__":' in path.read_text(encoding="utf-8")}
    assert runnable - {"__main__"} == set(BENCHMARKS), "benchmarks/__init__.py lists them all"
    documented = {(command.words[2], tuple(command.words[3:]))
                  for command in benchmark_commands() if command.path == BENCHMARKS_DOC}
    for name in BENCHMARKS:
        assert (f"benchmarks.{name}", ("--quick",)) in documented, \
            f"docs/benchmarks.md gives python3 -m benchmarks.{name} --quick"
    assert ("benchmarks", ("--quick",)) in documented, f"docs/benchmarks.md gives {RUN_ALL}"


@pytest.mark.heavy
def test_every_quick_variant_runs_through_the_documented_command() -> None:
    """One run of every quick variant, two at a time (about a minute on 2 cores)."""
    command = next(command for command in benchmark_commands() if command.text == RUN_ALL)
    result = subprocess.run([sys.executable, *command.words[1:]], cwd=ROOT, text=True,
                            capture_output=True, timeout=900,
                            env=dict(os.environ, PYTHONUNBUFFERED="1"))
    assert result.returncode == 0, result.stdout[-6000:] + result.stderr[-3000:]
    summary = result.stdout.splitlines()
    for name in BENCHMARKS:
        assert any(line.split()[:2] == [name, "ok"] for line in summary), name
    assert "Traceback" not in result.stdout, result.stdout[-6000:]


def test_a_quick_variant_past_its_time_is_stopped_and_counts_as_failed() -> None:
    result = subprocess.run([sys.executable, "-m", "benchmarks", "--quick", "--timeout", "0.5",
                             "modes"], cwd=ROOT, text=True, capture_output=True, timeout=60)
    assert result.returncode == 1
    assert "stopped after 0.5 s (--timeout)" in result.stdout
    assert result.stdout.splitlines()[-1].endswith("; FAILED: modes"), result.stdout


def test_a_benchmark_path_is_refused_with_where_it_is_written(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text("Run `python3 benchmarks/bt_tick.py --quick`, or:\n\n```sh\n"
                    "python3 -m benchmarks.bt_tick \\\n    --quick   # a few seconds\n```\n")
    found = doc_commands("python3", documents=(page,))
    assert [(command.line, command.text) for command in found] == [
        (1, "python3 benchmarks/bt_tick.py --quick"),
        (4, "python3 -m benchmarks.bt_tick --quick")]


def cyborg_words(command: DocCommand) -> list[list[str]]:
    """The ``cyborg`` commands of a code block's line, as argument lists: each part of a ``&&``
    chain, up to a pipe or a redirection, ``python3 -m cyborg`` as ``cyborg``. A synopsis
    (``cyborg router [--listen EP]``) describes a command's forms and gives none."""
    found = []
    for part in command.text.split("&&"):
        words = shlex.split(part.replace("python3 -m cyborg ", "cyborg ", 1))
        for end in ("|", ">", "&"):
            words = words[:words.index(end)] if end in words else words
        if words[:1] == ["cyborg"] and not any(word.startswith("[") for word in words):
            found.append(words[1:])
    return found


def test_every_cyborg_command_of_a_code_block_is_one_the_command_line_takes() -> None:
    commands = [command for command in doc_commands("cyborg", "python3") if command.fenced]
    cli, refused, parsed = build_parser(), [], 0
    for command in commands:
        for args in cyborg_words(command):
            errors = io.StringIO()
            try:
                with contextlib.redirect_stderr(errors), contextlib.redirect_stdout(io.StringIO()):
                    cli.parse_args(args)
                parsed += 1
            except SystemExit as refusal:
                if refusal.code:
                    refused.append(f"{command.where}: {command.text}\n    {errors.getvalue()}")
    assert parsed >= 50, "the README and docs give dozens of cyborg commands"
    assert not refused, "\n".join(refused)


def test_every_other_python_command_names_modules_and_files_that_exist() -> None:
    """``python3 -m MODULE`` names an importable module, and a file or folder it is given (a
    word with a slash or a file suffix) is in the checkout; what each does is tested where its
    module is."""
    checked, missing = 0, []
    for command in doc_commands("python3"):
        for part in command.text.split("&&"):
            words = shlex.split(part)
            if words[:1] != ["python3"] or "benchmarks" in part:
                continue
            checked += 1
            if words[1] == "-m" and importlib.util.find_spec(words[2]) is None:
                missing.append(f"{command.where}: no module {words[2]}")
            files = [word for word in words[1:] if not word.startswith(("-", "."))
                     and ("/" in word or word.endswith((".py", ".txt", ".toml")))]
            missing += [f"{command.where}: no {name}" for name in files
                        if not (ROOT / name).exists()]
    assert checked >= 5
    assert not missing, "\n".join(missing)


def test_a_synopsis_and_a_pipe_are_read_as_the_shell_reads_them() -> None:
    def words(text: str) -> list[list[str]]:
        return cyborg_words(DocCommand(ROOT / "README.md", 1, text, fenced=True))
    assert words("cyborg bt dot t.json | dot -Tsvg > t.svg") == [["bt", "dot", "t.json"]]
    assert words("python3 -m pip install -e . && python3 -m cyborg up") == [["up"]]
    assert words("cyborg router [--listen EP] [--connect EP]") == []
    assert words('cyborg sim --map m.map --speed 10 &') == [["sim", "--map", "m.map", "--speed",
                                                            "10"]]


def github_anchor(heading: str) -> str:
    """The anchor GitHub gives a heading: lower case, punctuation dropped, spaces as hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def test_links_into_the_benchmarks_page_find_their_sections() -> None:
    headings = [line.lstrip("#") for line in BENCHMARKS_DOC.read_text().splitlines()
                if line.startswith("#")]
    anchors = {github_anchor(heading) for heading in headings}
    links = [(path, anchor) for path in (ROOT / "README.md", *(ROOT / "docs").glob("*.md"))
             for target, anchor in re.findall(r"\]\(((?:docs/)?benchmarks\.md)?#([^)]+)\)",
                                              path.read_text(encoding="utf-8"))
             if target or path == BENCHMARKS_DOC]
    assert len(links) >= 10
    lost = [f"{path.relative_to(ROOT)}: #{anchor}" for path, anchor in links
            if anchor not in anchors]
    assert not lost, "no such section in docs/benchmarks.md:\n" + "\n".join(lost)
    assert github_anchor(" The recorder's CPU on `cyborg up`'s default topics") == \
        "the-recorders-cpu-on-cyborg-ups-default-topics"
