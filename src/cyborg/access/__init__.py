"""Who may reach cyborg's servers (the web monitor, the Foxglove server) from a network.

:mod:`~cyborg.access.web_access` holds the rules both follow: the ``Host`` allow-list that
guards against DNS rebinding, the page's own origin, and the token read from a file or
``$CYBORG_MONITOR_TOKEN`` and compared in constant time. This package imports nothing else of
cyborg.
"""

from cyborg.access.web_access import (
    TOKEN_VARIABLE,
    HostPolicy,
    TokenError,
    own_origin,
    read_token,
    same_secret,
    split_authority,
)

__all__ = ["TOKEN_VARIABLE", "HostPolicy", "TokenError", "own_origin", "read_token",
           "same_secret", "split_authority"]
