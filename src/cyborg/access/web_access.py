"""Who may reach cyborg's servers: the ``Host`` allow-list, the page's own origin, the token.

The web monitor and the Foxglove server follow these rules (written for the monitor first).

**DNS rebinding.** A web page on ``rebind.attacker.example`` can make its name resolve to
127.0.0.1 after the page has loaded; its scripts then talk to a server on this machine *as the
same origin* (the browser sees ``rebind.attacker.example`` on both sides), and the server sees a
loopback client. Comparing ``Origin`` with ``Host`` cannot catch this: both say
``rebind.attacker.example``. What does is the ``Host`` header itself, which the browser always
sets to the name in the address bar: the server answers only names it knows to be its own
(:class:`HostPolicy`), and every other request gets ``403``, HTTP and WebSocket alike.

* Allowed always: ``localhost`` and ``*.localhost`` (browsers resolve these to loopback
  themselves, RFC 6761), this machine's host name, ``NAME.local`` and fully qualified name,
  and any IP address written as such (``127.0.0.1``, ``[::1]``, ``10.0.0.7``): a browser that
  sends an address as Host connected to that address, so there is no name to rebind.
* Allowed when the user says so: ``--allow-host NAME`` (repeatable); ``.example.org`` allows
  that domain and every name under it; ``*`` turns the check off (behind a reverse proxy that
  checks names itself).

**The page's own origin** (:func:`own_origin`) is the scheme, host and port of the address the
browser shows, which must be exactly those of the request: ``https://robot:8080`` is not the
origin of a page served over plain ``ws://robot:8080``.

**The token** (:func:`read_token`) is read from ``--token-file`` or ``$CYBORG_MONITOR_TOKEN``
(``--token`` still works, but shows in ``ps``); it is compared as UTF-8 bytes in constant time
(:func:`same_secret`), so any Unicode token works. One token serves the machine's servers.
"""

from __future__ import annotations

import contextlib
import hmac
import ipaddress
import logging
import os
import re
import socket
import stat
from collections.abc import Iterable, Mapping
from pathlib import Path
from urllib.parse import urlsplit

log = logging.getLogger("cyborg.access")

TOKEN_VARIABLE = "CYBORG_MONITOR_TOKEN"
TOKEN_FILE_LIMIT = 4096
"""A token file longer than this is not a token (bytes)."""

_AUTHORITY = re.compile(r"^(?:\[(?P<v6>[0-9A-Fa-f:.]+)\]|(?P<name>[A-Za-z0-9._-]+))"
                        r"(?::(?P<port>[0-9]{1,5}))?$")
DEFAULT_PORTS = {"http": 80, "https": 443, "ws": 80, "wss": 443}


class TokenError(ValueError):
    """The token cannot be read; the message says from where and why."""


def split_authority(value: str | None) -> tuple[str, int | None] | None:
    """``(host, port)`` of a ``Host`` header; None when it is not a plain ``host[:port]``.

    The host comes lower-cased, without a trailing dot, an IPv6 address without its brackets;
    the port is None when the header has none.
    """
    match = _AUTHORITY.match(value or "")
    if match is None:
        return None
    port = int(match["port"]) if match["port"] else None
    if port is not None and port > 65535:
        return None
    host = str(match["v6"] or match["name"]).lower().rstrip(".")
    if not host or (match["v6"] and not _is_address(host)):
        return None
    return host, port


def _is_address(host: str) -> bool:
    try:
        ipaddress.ip_address(host)
    except ValueError:
        return False
    return True


def this_machine_names() -> set[str]:
    """The names this machine goes by: its host name, ``NAME.local`` and its full name.

    The fully qualified name is asked of the resolver (``/etc/hosts`` usually answers); a
    resolver that fails leaves it out.
    """
    host = socket.gethostname().lower()
    names = {host, f"{host}.local"}
    with contextlib.suppress(OSError):  # a resolver that fails outright
        names.add(socket.getfqdn(host).lower())
    return {name for name in names if name}


class HostPolicy:
    """Which ``Host`` headers a server answers; see the module docstring.

    ``allowed``: names the user adds (``.domain`` for a domain and its names, ``*`` for any);
    ``own_names``: this machine's names (default: :func:`this_machine_names`); ``server``: what
    a refusal calls the server ("monitor", "Foxglove server").
    """

    def __init__(self, allowed: Iterable[str] = (), *,
                 own_names: Iterable[str] | None = None, server: str = "monitor") -> None:
        self.server = server
        extra = [name.strip().lower().rstrip(".") for name in allowed if name.strip()]
        self.any = "*" in extra
        self.names = {"localhost", *(own_names if own_names is not None
                                     else this_machine_names())}
        self.names.update(name for name in extra if not name.startswith("."))
        self.domains = tuple(name for name in extra if name.startswith("."))

    def allows(self, host_header: str | None) -> bool:
        """Whether a request whose ``Host`` header is ``host_header`` is for this server."""
        if self.any:
            return True
        parts = split_authority(host_header)
        if parts is None:
            return False
        host = parts[0]
        if _is_address(host) or host in self.names or host.endswith(".localhost"):
            return True
        return any(host == domain[1:] or host.endswith(domain) for domain in self.domains)

    def refusal(self, host_header: str | None) -> str:
        """What a refused request is told: why, and the option that would allow it."""
        parts = split_authority(host_header)
        if parts is None:
            return f"403: the Host header {host_header!r} is not a host name\n"
        return (f"403: this {self.server} does not answer to the name {parts[0]!r} (a guard "
                f"against DNS rebinding). If that is this machine's name, start the "
                f"{self.server} with --allow-host {parts[0]}\n")


def own_origin(origin: str, scheme: str, host_header: str | None) -> bool:
    """Whether a browser's ``Origin`` is the page the request is for.

    It is when it has the same scheme (``http`` for ``ws``, ``https`` for ``wss``), host and
    port (default ports filled in) as the request's ``scheme`` and ``Host`` header.
    """
    request = split_authority(host_header)
    if request is None or scheme not in DEFAULT_PORTS:
        return False
    try:
        parts = urlsplit(origin)
        origin_port = parts.port
    except ValueError:
        return False
    origin_scheme = parts.scheme.lower()
    if origin_scheme not in ("http", "https") or not parts.hostname or parts.path \
            or parts.username is not None or parts.password is not None:
        return False
    wanted_scheme = {"ws": "http", "wss": "https"}.get(scheme, scheme)
    host, port = request
    return (origin_scheme, parts.hostname.lower().rstrip("."),
            origin_port or DEFAULT_PORTS[origin_scheme]) == (
        wanted_scheme, host, port or DEFAULT_PORTS[scheme])


def same_secret(given: str | None, expected: str | None) -> bool:
    """Whether two secrets are equal, compared in constant time as UTF-8 bytes.

    Bytes, because ``hmac.compare_digest`` on ``str`` refuses non-ASCII text. Either missing or
    empty: False.
    """
    if not given or not expected:
        return False
    return hmac.compare_digest(given.encode("utf-8", "surrogatepass"),
                               expected.encode("utf-8", "surrogatepass"))


def read_token(token: str | None = None, token_file: str | Path | None = None, *,
               environ: Mapping[str, str] | None = None) -> str | None:
    """The control token; None when there is none.

    It is ``token`` if given, else the first line of ``token_file``, else
    ``$CYBORG_MONITOR_TOKEN``. A token file other users can read is used, with a warning.
    Raises :class:`TokenError` when the file cannot be read or is empty.
    """
    if token:
        return token
    if token_file:
        return _token_from_file(Path(token_file).expanduser())
    environ = os.environ if environ is None else environ
    return environ.get(TOKEN_VARIABLE) or None


def _token_from_file(path: Path) -> str:
    try:
        # O_NONBLOCK: opening a FIFO with no writer waited for one, holding the start-up
        with os.fdopen(os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC), "rb") as file:
            status = os.fstat(file.fileno())
            if not stat.S_ISREG(status.st_mode):
                raise TokenError(f"token file {path}: not a regular file")
            raw = file.read(TOKEN_FILE_LIMIT + 1)
    except FileNotFoundError:
        raise TokenError(f"token file {path}: missing") from None
    except OSError as exc:
        raise TokenError(f"token file {path}: {exc.strerror}") from None
    if len(raw) > TOKEN_FILE_LIMIT:
        raise TokenError(f"token file {path}: longer than {TOKEN_FILE_LIMIT} bytes; a token "
                         "is one line")
    try:
        lines = raw.decode("utf-8").splitlines()
    except UnicodeDecodeError:
        raise TokenError(f"token file {path}: not UTF-8 text") from None
    token = lines[0].strip() if lines else ""
    if not token:
        raise TokenError(f"token file {path}: empty (write the token on its first line)")
    if status.st_mode & (stat.S_IRGRP | stat.S_IROTH):
        log.warning("token file %s: other users can read it (chmod 600 %s)", path, path)
    return token
