"""Who may reach the monitor at all: the rules of :mod:`cyborg.access.web_access`, named here.

The ``Host`` allow-list (a guard against DNS rebinding), the page's own origin and the token
are the same for the monitor and the Foxglove server, so they live in :mod:`cyborg.access`;
the monitor's modules import them from here.
"""

from cyborg.access.web_access import (
    DEFAULT_PORTS,
    TOKEN_FILE_LIMIT,
    TOKEN_VARIABLE,
    HostPolicy,
    TokenError,
    own_origin,
    read_token,
    same_secret,
    split_authority,
    this_machine_names,
)

__all__ = ["DEFAULT_PORTS", "TOKEN_FILE_LIMIT", "TOKEN_VARIABLE", "HostPolicy", "TokenError",
           "own_origin", "read_token", "same_secret", "split_authority", "this_machine_names"]
