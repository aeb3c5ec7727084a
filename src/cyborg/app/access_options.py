"""Who may open and control cyborg's servers, from the command line.

For ``cyborg monitor``, ``cyborg foxglove`` and ``cyborg up``: the names the server answers to
and the token that lets other machines in. See docs/security.md.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

TOKEN_IN_PS = ("cyborg: warning: --token shows in `ps` to every user of this machine; prefer "
               "--token-file PATH or CYBORG_MONITOR_TOKEN")
"""The warning ``--token`` gets."""


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


def add_token_option(parser: argparse.ArgumentParser) -> None:
    """``--token``, for the commands that start one server (not ``cyborg up``)."""
    parser.add_argument("--token", default=None,
                        help="the token itself (shows in `ps`: prefer --token-file or "
                             "$CYBORG_MONITOR_TOKEN)")


def add_token(args: argparse.Namespace, parameters: dict[str, Any]) -> None:
    """Puts ``--token`` into ``parameters``, warning that it shows in ``ps``.

    It is passed on in memory only: the servers never make it a bus parameter.
    """
    if args.token:
        print(TOKEN_IN_PS, file=sys.stderr)
        parameters["token"] = args.token
