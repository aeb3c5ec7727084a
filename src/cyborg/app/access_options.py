"""Who may open and control the web monitor, from the command line.

For ``cyborg monitor`` and ``cyborg up``: the names the page answers to and the token that lets
other machines control. See docs/security.md.
"""

from __future__ import annotations

import argparse
from typing import Any


def add_access_options(parser: argparse.ArgumentParser) -> None:
    """``--allow-host`` and ``--token-file``, for ``cyborg monitor`` and ``cyborg up``."""
    parser.add_argument("--allow-host", action="append", default=[], metavar="NAME",
                        help="a name the page may be opened as, beside this machine's names "
                             "and addresses (repeatable; .example.org: the domain and its "
                             "names)")
    parser.add_argument("--token-file", default=None, metavar="PATH",
                        help="file whose first line is the token that lets pages on other "
                             "machines control (?token=...); default $CYBORG_MONITOR_TOKEN")


def access_parameters(args: argparse.Namespace) -> dict[str, Any]:
    """The monitor's launch parameters for ``--allow-host`` and ``--token-file``."""
    parameters: dict[str, Any] = {}
    if args.allow_host:
        parameters["allow_hosts"] = list(args.allow_host)
    if args.token_file:
        parameters["token_file"] = str(args.token_file)
    return parameters
