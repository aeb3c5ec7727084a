"""How a process joins the Zenoh network: rmw_zenoh's topology and environment variables.

By default every process is a Zenoh *peer* that listens on a random loopback port, connects to a
router at ``tcp/127.0.0.1:7447`` and never scouts by multicast, so nothing leaves the machine.
Peers find each other through the router (gossip) and then talk directly. This is the topology
of rmw_zenoh, so a ROS 2 node started with ``RMW_IMPLEMENTATION=rmw_zenoh_cpp`` on the same
machine and a ``cyborg`` process share one graph as soon as one router runs (``cyborg router``,
``ros2 run rmw_zenoh_cpp rmw_zenohd``, or ``cyborg up``, which hosts one).

Environment (read when a :class:`BusConfig` is built from it):

``CYBORG_CONNECT``
    comma-separated endpoints to connect to instead of the local router, e.g.
    ``tcp/192.168.1.10:7447`` to join the robot's router from a laptop.
``ZENOH_SESSION_CONFIG_URI``
    a JSON5 Zenoh configuration file used as the base, as in rmw_zenoh.
``ZENOH_CONFIG_OVERRIDE``
    ``key=value;key=value`` settings applied last, as in rmw_zenoh
    (e.g. ``transport/shared_memory/enabled=false``).
``ROS_DOMAIN_ID``
    the domain, the first chunk of every key (see :func:`cyborg.bus.wire.domain_id`).
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import zenoh

DEFAULT_ROUTER = "tcp/127.0.0.1:7447"
CONNECT_ENV = "CYBORG_CONNECT"
CONFIG_FILE_ENV = "ZENOH_SESSION_CONFIG_URI"
OVERRIDE_ENV = "ZENOH_CONFIG_OVERRIDE"


class BusConfigError(ValueError):
    """A connection setting that cannot be used; the message names the setting."""


@dataclass(frozen=True)
class BusConfig:
    """Where a session listens and connects, and in which Zenoh mode.

    ``mode="router"`` makes the session itself a router (``cyborg router`` and ``cyborg up``).
    ``doorbell=False`` sends shared-memory slot references to processes on this machine
    through Zenoh instead of by Unix datagram (:mod:`cyborg.bus.doorbell`).
    """

    mode: str = "peer"
    connect: tuple[str, ...] = (DEFAULT_ROUTER,)
    listen: tuple[str, ...] = ("tcp/127.0.0.1:0",)
    config_file: Path | None = None
    overrides: tuple[tuple[str, str], ...] = ()
    extra: Mapping[str, object] = field(default_factory=dict)
    doorbell: bool = True

    @classmethod
    def from_environment(cls, connect: Sequence[str] = (),
                         environ: Mapping[str, str] | None = None) -> BusConfig:
        """The default peer set-up, changed by ``connect`` (e.g. ``--connect``) or the env."""
        env = os.environ if environ is None else environ
        endpoints = tuple(connect) or _split(env.get(CONNECT_ENV, ""), ",") or (DEFAULT_ROUTER,)
        config_file = Path(env[CONFIG_FILE_ENV]) if env.get(CONFIG_FILE_ENV) else None
        overrides = tuple(_override(item) for item in _split(env.get(OVERRIDE_ENV, ""), ";"))
        return cls(connect=endpoints, config_file=config_file, overrides=overrides)

    @classmethod
    def router(cls, listen: Sequence[str] = (DEFAULT_ROUTER,),
               connect: Sequence[str] = ()) -> BusConfig:
        """A router listening on ``listen`` (all interfaces: ``tcp/[::]:7447``)."""
        return cls(mode="router", connect=tuple(connect), listen=tuple(listen))

    @classmethod
    def isolated(cls) -> BusConfig:
        """A session that talks to no one else: one process, no sockets opened."""
        return cls(connect=(), listen=())

    def to_zenoh(self) -> zenoh.Config:
        """The Zenoh configuration; errors name the file or setting at fault."""
        if self.mode not in ("peer", "router", "client"):
            raise BusConfigError(f"mode {self.mode!r}: expected peer, router or client")
        for endpoint in (*self.connect, *self.listen):
            if "/" not in endpoint:
                raise BusConfigError(f"endpoint {endpoint!r}: expected PROTOCOL/HOST:PORT, "
                                     "e.g. tcp/192.168.1.10:7447")
        if self.config_file is not None:
            try:
                config = zenoh.Config.from_file(str(self.config_file))
            except Exception as exc:
                raise BusConfigError(f"{CONFIG_FILE_ENV}={self.config_file}: {exc}") from exc
        else:
            config = zenoh.Config()
        settings: dict[str, object] = {
            "mode": self.mode,
            "connect/endpoints": list(self.connect),
            "listen/endpoints": list(self.listen),
            "scouting/multicast/enabled": False,
            "timestamping/enabled": True,  # transient-local caches need timestamps
        }
        settings.update(self.extra)
        for key, value in settings.items():
            config.insert_json5(key, json.dumps(value))
        for key, text in self.overrides:
            try:
                config.insert_json5(key, text)
            except Exception as exc:
                raise BusConfigError(f"{OVERRIDE_ENV}: {key}={text}: {exc}") from exc
        return config


def _split(text: str, separator: str) -> tuple[str, ...]:
    return tuple(part.strip() for part in text.split(separator) if part.strip())


def _override(item: str) -> tuple[str, str]:
    key, sep, value = item.partition("=")
    if not sep or not key.strip():
        raise BusConfigError(f"{OVERRIDE_ENV}: {item!r} is not KEY=VALUE")
    return key.strip(), value.strip()
