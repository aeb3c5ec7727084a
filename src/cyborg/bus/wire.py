"""rmw_zenoh's wire conventions (Jazzy and later), so ROS 2 peers see us as ROS 2 nodes.

* data keys — ``<domain>/<name>/<dds type>/<type hash>`` (:func:`data_key`);
* liveliness tokens — ``@ros2_lv/...`` for nodes and endpoints, the graph that ``ros2 node
  list`` reads (:func:`node_token`, :func:`endpoint_token`);
* the QoS string inside endpoint tokens, with rmw_zenoh's defaults left empty (:class:`Qos`);
* GIDs — the XXH3-128 of an entity's liveliness key (:func:`gid`);
* the 33-byte attachment on every sample, request and reply (:class:`Attachment`).

Everything here is pure and byte-exact; the facts come from rmw_zenoh's design document and
liveliness/attachment sources.
"""

from __future__ import annotations

import os
import struct
from dataclasses import dataclass
from enum import IntEnum, StrEnum

import xxhash

LIVELINESS_PREFIX = "@ros2_lv"
DOMAIN_ENV = "ROS_DOMAIN_ID"
MAX_DOMAIN_ID = 232


def domain_id(environ: dict[str, str] | None = None) -> int:
    """The ROS domain from ``ROS_DOMAIN_ID`` (default 0). Raises ValueError naming the bad value."""
    text = (os.environ if environ is None else environ).get(DOMAIN_ENV, "").strip()
    if not text:
        return 0
    if not text.isdigit() or int(text) > MAX_DOMAIN_ID:
        raise ValueError(f"{DOMAIN_ENV}={text!r}: expected a number from 0 to {MAX_DOMAIN_ID}")
    return int(text)


def fully_qualified(namespace: str, name: str) -> str:
    """``/ns`` + ``name`` -> ``/ns/name``; an absolute ``name`` is kept; ``~`` is not supported."""
    if not name or name.startswith("~"):
        raise ValueError(f"invalid topic or service name {name!r}")
    if name.startswith("/"):
        return name
    namespace = "/" + namespace.strip("/") if namespace.strip("/") else ""
    return f"{namespace}/{name}"


def dds_type_name(type_name: str) -> str:
    """``std_msgs/msg/String`` -> ``std_msgs::msg::dds_::String_``.

    A service ``pkg/srv/X`` becomes ``pkg::srv::dds_::X_`` (no Request/Response suffix).
    """
    package, kind, name = type_name.split("/")
    return f"{package}::{kind}::dds_::{name}_"


def data_key(domain: int, fq_name: str, type_name: str, type_hash: str) -> str:
    """The key a topic's samples, or a service's queries, are exchanged on."""
    return f"{domain}/{fq_name.strip('/')}/{dds_type_name(type_name)}/{type_hash}"


def mangle(part: str) -> str:
    """A name as one liveliness key chunk: ``/`` becomes ``%``, empty becomes ``%``."""
    return part.replace("/", "%") if part else "%"


def unmangle(part: str) -> str:
    """The inverse of :func:`mangle`: ``%`` alone becomes empty, any other ``%`` a ``/``."""
    return "" if part == "%" else part.replace("%", "/")


class Reliability(IntEnum):
    """QoS reliability, numbered as in rmw_zenoh's QoS string."""

    RELIABLE = 1
    BEST_EFFORT = 2


class Durability(IntEnum):
    """QoS durability, numbered as in rmw_zenoh's QoS string; transient-local is latched."""

    TRANSIENT_LOCAL = 1
    VOLATILE = 2


class History(IntEnum):
    """QoS history, numbered as in rmw_zenoh's QoS string."""

    KEEP_LAST = 1
    KEEP_ALL = 2


INFINITE = (9223372036, 854775807)
"""rmw_zenoh's infinite duration, (seconds, nanoseconds)."""


@dataclass(frozen=True)
class Qos:
    """Quality of service of an endpoint. Defaults are rmw_zenoh's."""

    reliability: Reliability = Reliability.RELIABLE
    durability: Durability = Durability.VOLATILE
    history: History = History.KEEP_LAST
    depth: int = 42
    deadline: tuple[int, int] = INFINITE
    lifespan: tuple[int, int] = INFINITE
    liveliness: int = 1  # AUTOMATIC
    lease: tuple[int, int] = INFINITE

    @classmethod
    def latched(cls, depth: int = 1) -> Qos:
        """Transient-local: a late subscriber gets the last ``depth`` samples."""
        return cls(durability=Durability.TRANSIENT_LOCAL, depth=depth)

    def to_keyexpr(self) -> str:
        """The QoS chunk of an endpoint token; fields equal to the default are left empty."""
        default = Qos()

        def pick(value: object, base: object) -> str:
            if value == base:
                return ""
            return str(int(value)) if isinstance(value, IntEnum) else str(value)

        def duration(value: tuple[int, int], base: tuple[int, int]) -> str:
            return "," if value == base else f"{value[0]},{value[1]}"

        return ":".join([
            pick(self.reliability, default.reliability),
            pick(self.durability, default.durability),
            f"{pick(self.history, default.history)},{pick(self.depth, default.depth)}",
            duration(self.deadline, default.deadline),
            duration(self.lifespan, default.lifespan),
            f"{pick(self.liveliness, default.liveliness)},"
            f"{duration(self.lease, default.lease)}",
        ])


class EntityKind(StrEnum):
    """The kind of a graph entity, as its liveliness token spells it."""

    NODE = "NN"
    PUBLISHER = "MP"
    SUBSCRIPTION = "MS"
    SERVICE_SERVER = "SS"
    SERVICE_CLIENT = "SC"


def node_token(domain: int, zid: str, node_id: int, namespace: str, node: str,
               enclave: str = "") -> str:
    """Liveliness key announcing a node."""
    return "/".join([LIVELINESS_PREFIX, str(domain), zid, str(node_id), str(node_id),
                     EntityKind.NODE.value, mangle(enclave), mangle(namespace), node])


def endpoint_token(domain: int, zid: str, node_id: int, entity_id: int, kind: EntityKind,
                   namespace: str, node: str, fq_name: str, type_name: str, type_hash: str,
                   qos: Qos, enclave: str = "") -> str:
    """Liveliness key announcing a publisher, subscription, service server or client."""
    return "/".join([LIVELINESS_PREFIX, str(domain), zid, str(node_id), str(entity_id),
                     kind.value, mangle(enclave), mangle(namespace), node, mangle(fq_name),
                     dds_type_name(type_name), type_hash, qos.to_keyexpr()])


def gid(liveliness_key: str) -> bytes:
    """An entity's 16-byte GID: XXH3-128 (seed 0) of its liveliness key, little endian."""
    return xxhash.xxh3_128_intdigest(liveliness_key.encode()).to_bytes(16, "little")


_ATTACHMENT = struct.Struct("<qqB16s")
ATTACHMENT_SIZE = _ATTACHMENT.size


@dataclass(frozen=True)
class Attachment:
    """Sequence number (from 1), source timestamp (ns since the epoch) and source GID."""

    sequence: int
    timestamp_ns: int
    gid: bytes

    def encode(self) -> bytes:
        """The 33-byte wire form; raises ValueError unless ``gid`` has 16 bytes."""
        if len(self.gid) != 16:
            raise ValueError(f"a GID has 16 bytes, not {len(self.gid)}")
        return _ATTACHMENT.pack(self.sequence, self.timestamp_ns, 16, self.gid)

    @classmethod
    def decode(cls, data: bytes | bytearray | memoryview) -> Attachment:
        """Parse an attachment; ValueError if it is not rmw_zenoh's 33-byte form."""
        if len(data) != ATTACHMENT_SIZE:
            raise ValueError(f"an attachment has {ATTACHMENT_SIZE} bytes, not {len(data)}")
        sequence, timestamp, length, source = _ATTACHMENT.unpack(bytes(data))
        if length != 16:
            raise ValueError(f"attachment GID length is {length}, expected 16")
        return cls(sequence, timestamp, source)
