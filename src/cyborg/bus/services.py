"""Services: request/response over a Zenoh queryable, exactly as rmw_zenoh does it.

The server declares a complete queryable on the service key (its type hash is the *service*
hash); a client sends a ``get`` with the CDR request and the 33-byte attachment, and the server
replies on the same key with the request's sequence number and the client's GID echoed.

Unlike ROS 2, a handler's exception reaches the caller: the server answers with a Zenoh error
reply naming the exception, and :meth:`ServiceClient.call` raises :class:`ServiceError` with it.

    def add(request):
        return AddTwoInts_Response(sum=request.a + request.b)
    node.create_service("add_two_ints", "example_interfaces/srv/AddTwoInts", add)
    client = node.create_client("add_two_ints", "example_interfaces/srv/AddTwoInts")
    client.call(AddTwoInts_Request(a=2, b=40), timeout=2.0).sum   # 42
"""

from __future__ import annotations

import itertools
import logging
import threading
import time
from collections.abc import Callable
from concurrent.futures import Future
from typing import TYPE_CHECKING, Any

import zenoh

from cyborg.bus.wire import (
    Attachment,
    EntityKind,
    Qos,
    data_key,
    endpoint_token,
    fully_qualified,
    gid,
)

if TYPE_CHECKING:
    from cyborg.bus.node import Node

log = logging.getLogger("cyborg.bus")

SERVICE_QOS = Qos(depth=1000)  # what rmw_zenoh announces for services: reliable, keep-last


class ServiceError(RuntimeError):
    """A service call failed: no server, no reply in time, or the handler raised."""


class ServiceTimeoutError(ServiceError):
    """No reply came within the timeout."""


class _ServiceEndpoint:
    def __init__(self, node: Node, name: str, service_type: str, kind: EntityKind) -> None:
        context = node.context
        if f"{service_type}_Request" not in context.types:
            raise KeyError(f"{name}: unknown service type {service_type!r}")
        self.node, self.context = node, context
        self.name = fully_qualified(node.namespace, name)
        self.service_type = service_type
        type_hash = context.types.hash(service_type)
        self.key = data_key(context.domain, self.name, service_type, type_hash)
        self.token_key = endpoint_token(context.domain, context.zid, node.id, context.next_id(),
                                        kind, node.namespace, node.name, self.name,
                                        service_type, type_hash, SERVICE_QOS)
        self.gid = gid(self.token_key)
        self.request_class = context.types.message_class(f"{service_type}_Request")
        self.response_class = context.types.message_class(f"{service_type}_Response")
        self._token = context.session.liveliness().declare_token(self.token_key)
        self._closed = False

    def _undeclare(self) -> bool:
        if self._closed or self.context.closed:
            self._closed = True
            return False
        self._closed = True
        self._token.undeclare()
        return True


class Responder:
    """Answers one request, now or later (from any thread), exactly once."""

    def __init__(self, server: ServiceServer, query: zenoh.Query, attachment: Attachment) -> None:
        self._server, self._query, self._attachment = server, query, attachment
        self._done = threading.Lock()

    @property
    def caller_gid(self) -> bytes:
        """The calling client's 16-byte GID (from the request's attachment): which client
        asked, e.g. to release what it set up once its liveliness token is gone."""
        return self._attachment.gid

    def reply(self, response: Any) -> None:
        server = self._server
        if not isinstance(response, server.response_class):
            self.fail(TypeError(f"the handler returned {type(response).__name__}, "
                                f"not {server.service_type}_Response"))
            return
        if not self._done.acquire(blocking=False):
            return
        payload = server.context.types.serialize(response, f"{server.service_type}_Response")
        reply = Attachment(self._attachment.sequence, time.time_ns(), self._attachment.gid)
        self._query.reply(self._query.key_expr, payload.obj, attachment=reply.encode())
        self._query.drop()

    def fail(self, error: BaseException) -> None:
        if not self._done.acquire(blocking=False):
            return
        self._query.reply_err(f"{type(error).__name__}: {error}".encode())
        self._query.drop()


class ServiceServer(_ServiceEndpoint):
    """Serves requests with ``handler(request) -> response`` on the node's thread.

    With ``deferred=True`` the handler is ``handler(request, responder)`` and answers through
    ``responder.reply(response)`` whenever it is ready (an action's get_result does this).
    """

    def __init__(self, node: Node, name: str, service_type: str,
                 handler: Callable[..., Any], *, deferred: bool = False) -> None:
        super().__init__(node, name, service_type, EntityKind.SERVICE_SERVER)
        self.handler, self.deferred = handler, deferred
        self.handled = 0
        self._queryable = self.context.session.declare_queryable(
            self.key, self._on_query, complete=True)

    def _on_query(self, query: zenoh.Query) -> None:
        try:
            attachment = Attachment.decode(query.attachment.to_bytes()) if query.attachment \
                else Attachment(0, 0, bytes(16))
            payload = query.payload.to_bytes() if query.payload is not None else b""
            request = self.context.types.deserialize(payload, f"{self.service_type}_Request")
        except Exception as exc:
            self.context.drop(f"{self.name}: cannot decode request", str(exc))
            query.reply_err(f"cannot decode {self.service_type} request: {exc}".encode())
            query.drop()
            return
        self.node.callbacks.submit(self._handle, Responder(self, query, attachment), request)

    def _handle(self, responder: Responder, request: Any) -> None:
        self.handled += 1
        try:
            if self.deferred:
                self.handler(request, responder)
            else:
                responder.reply(self.handler(request))
        except Exception as exc:
            log.error("service %s: handler raised %s: %s", self.name, type(exc).__name__, exc,
                      exc_info=True)
            responder.fail(exc)

    def destroy(self) -> None:
        if self._undeclare():
            self._queryable.undeclare()


class ServiceClient(_ServiceEndpoint):
    """Calls a service: :meth:`call` blocks, :meth:`call_async` returns a Future."""

    def __init__(self, node: Node, name: str, service_type: str) -> None:
        super().__init__(node, name, service_type, EntityKind.SERVICE_CLIENT)
        self._sequence = itertools.count(1)

    def service_is_ready(self) -> bool:
        return self.context.graph.count(self.name, EntityKind.SERVICE_SERVER) > 0

    def wait_for_service(self, timeout: float = 5.0) -> bool:
        """Wait until a server for this service is in the graph."""
        return self.context.graph.wait_for(lambda graph: self.service_is_ready(), timeout)

    def call(self, request: Any, timeout: float = 5.0) -> Any:
        """Send ``request`` and return the response; raise :class:`ServiceError` on failure."""
        if not isinstance(request, self.request_class):
            raise TypeError(f"call {self.name}: expected {self.service_type}_Request, "
                            f"got {type(request).__name__}")
        payload = self.context.types.serialize(request, f"{self.service_type}_Request")
        attachment = Attachment(next(self._sequence), time.time_ns(), self.gid)
        replies = self.context.session.get(
            self.key, payload=payload.obj, attachment=attachment.encode(),
            target=zenoh.QueryTarget.ALL_COMPLETE, consolidation=zenoh.ConsolidationMode.NONE,
            timeout=timeout)
        started = time.monotonic()
        for reply in replies:
            if reply.ok is not None:
                try:
                    return self.context.types.deserialize(reply.ok.payload.to_bytes(),
                                                          f"{self.service_type}_Response")
                except Exception as exc:
                    raise ServiceError(f"service {self.name}: cannot decode the response: "
                                       f"{exc}") from exc
            if reply.err is not None:
                text = reply.err.payload.to_string()
                if text == "Timeout":
                    break
                raise ServiceError(f"service {self.name} failed: {text}")
        if time.monotonic() - started >= timeout * 0.9:
            raise ServiceTimeoutError(f"service {self.name}: no reply within {timeout:g} s")
        raise ServiceError(f"service {self.name} ({self.service_type}) is not available; "
                           "is its server running? (`cyborg service list`)")

    def call_async(self, request: Any, timeout: float = 5.0) -> Future[Any]:
        """Like :meth:`call`, on a worker thread; the Future holds the response or the error."""
        return self.context.calls.submit(self.call, request, timeout)

    def destroy(self) -> None:
        self._undeclare()
