"""Finding the line of a table or key in TOML text, strings and multi-line values included."""

from __future__ import annotations

import tomllib

from cyborg.modes.toml_lines import TomlLines

TEXT = '''\
# a comment with [modes.fake] and key = 1
project = "p.json"
description = """
[modes.inside_a_string]
tree = "not a key"
"""
modes.quick.tree = "x"          # a dotted key
[modes.normal]
tree = "patrol"
[modes."low power"]
tree = 'charge'
list = [
  "a",   # inner = 1
  "b",
]
after = 1
[[transitions]]
from = "normal"
[[transitions]]
from = "low power"
when = "a == '[x]'"
[modes.inline]
sub = { tree = "demo", then = "normal" }
'''


def test_headers_keys_and_array_tables_have_their_lines() -> None:
    tomllib.loads(TEXT)  # the sample is valid TOML
    lines = TomlLines(TEXT)
    assert lines.line("project") == 2
    assert lines.line("description") == 3
    assert lines.line("modes", "quick", "tree") == 7
    assert lines.line("modes", "normal") == 8
    assert lines.line("modes", "normal", "tree") == 9
    assert lines.line("modes", "low power") == 10
    assert lines.line("modes", "low power", "tree") == 11
    assert lines.line("modes", "low power", "after") == 16
    assert lines.line("transitions") == 17
    assert lines.line("transitions", 0, "from") == 18
    assert lines.line("transitions", 1) == 19
    assert lines.line("transitions", 1, "when") == 21


def test_strings_comments_and_values_are_never_keys() -> None:
    lines = TomlLines(TEXT)
    assert lines.line("modes", "inside_a_string") is None
    assert lines.line("modes", "fake") is None
    assert lines.line("modes", "low power", "inner") == 10  # only the table is found
    assert lines.line("modes", "inline", "sub", "tree") == 23  # the inline table's key


def test_unknown_paths_fall_back_to_the_nearest_table() -> None:
    lines = TomlLines(TEXT)
    assert lines.line("transitions", 1, "guard") == 19
    assert lines.line("nothing") is None
