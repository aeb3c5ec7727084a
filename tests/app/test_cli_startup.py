"""The command line imports a command's module only when that command runs: `cyborg --help` lists
every command from cyborg.app.command_table alone, importing no bus, numpy, OpenCV,
onnxruntime or Foxglove; each command is added by the module the table names, with the table's
help line."""

from __future__ import annotations

import argparse
import subprocess
import sys

import pytest

from cyborg.app.cli import build_parser
from cyborg.app.command_table import COMMANDS, command_in

HEAVY = ("zenoh", "numpy", "cv2", "onnxruntime", "foxglove", "scipy", "numba", "starlette")


def subcommands(parser: argparse.ArgumentParser) -> argparse._SubParsersAction:  # type: ignore[type-arg]
    (action,) = [action for action in parser._actions
                 if isinstance(action, argparse._SubParsersAction)]
    return action


def test_help_imports_none_of_the_heavy_libraries() -> None:
    script = ("import sys\nfrom cyborg.app.cli import main\ntry:\n    main(['--help'])\n"
              "except SystemExit as exc:\n    assert exc.code == 0\n"
              f"print(sorted(name for name in {HEAVY!r} if name in sys.modules))")
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                            timeout=60, check=True)
    *listing, imported = result.stdout.strip().splitlines()
    assert imported == "[]", f"cyborg --help imported {imported}"
    text = "\n".join(listing)
    for name, command in COMMANDS.items():
        assert name in text and command.help.split()[0] in text


def test_every_command_comes_from_its_module_with_the_tables_help() -> None:
    full = subcommands(build_parser())
    assert list(full.choices) == list(COMMANDS)
    helps = {action.dest: action.help for action in full._choices_actions}
    assert helps == {name: command.help for name, command in COMMANDS.items()}
    for name in COMMANDS:
        one = subcommands(build_parser(name))
        assert list(one.choices) == list(COMMANDS), "every command is listed"
        assert len(one.choices[name]._actions) > 1, f"{name} is built in full"
        module = sys.modules[f"cyborg.app.{COMMANDS[name].module}"]
        assert hasattr(module, "add_parser")


@pytest.mark.parametrize(("argv", "command"), [
    (["bt", "validate", "x"], "bt"), (["-v", "up"], "up"), (["-vv", "--verbose", "topic", "list"],
                                                             "topic"),
    (["--help"], None), ([], None), (["nonsense"], None), (["-v", "nonsense", "up"], None)])
def test_the_command_is_the_first_word_that_is_not_an_option(argv: list[str],
                                                              command: str | None) -> None:
    assert command_in(argv) == command


def test_an_unknown_command_is_a_usage_error_listing_the_commands(
        capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as ended:
        build_parser(None).parse_args(["nonsense"])
    assert ended.value.code == 2
    assert "invalid choice: 'nonsense'" in capsys.readouterr().err
