"""Services: request/response over a Zenoh queryable, exactly as rmw_zenoh does it.

The server declares a complete queryable on the service key (its type hash is the *service*
hash); a client sends a ``get`` with the CDR request and the 33-byte attachment, and the server
replies on the same key with the request's sequence number and the client's GID echoed.

Unlike ROS 2, a failure reaches the caller as one line, never as a traceback, and the server
logs where it happened:

* a request that does not fit the service's request type (a wrong field type on the client, a
  payload that does not decode on the server) never reaches the handler: the client raises
  :class:`RequestError` before sending, the server answers ``bad request: ...``;
* a handler refuses a request by raising :class:`RequestError` naming the field (``goal.x: nan
  is not a finite number``); checks in :attr:`ServiceServer.checks` run before the handler;
  the caller gets ``bad request: goal.x: ...``, the server logs one warning line;
* any other exception in a handler gives the caller ``ExceptionType: first line of its
  message``; the server logs the traceback the first time per exception type, then one line;
* a response that does not fit the response type is an error reply naming the field, at once,
  not a timeout.

    from cyborg.bus.msgs.example_interfaces.srv import AddTwoInts

    def add(request: AddTwoInts_Request) -> AddTwoInts_Response:
        return AddTwoInts.Response(sum=request.a + request.b)
    node.create_service("add_two_ints", AddTwoInts, add)
    client = node.create_client("add_two_ints", AddTwoInts)
    client.call(AddTwoInts.Request(a=2, b=40), timeout=2.0).sum   # 42

Made from a :class:`~cyborg.bus.typed.ServiceType`, servers and clients are generic in its
request and response classes (``ServiceClient[AddTwoInts_Request, AddTwoInts_Response]``), so
mypy checks the handler and what :meth:`ServiceClient.call` is given and returns.
"""

from __future__ import annotations

import itertools
import logging
import threading
import time
from collections.abc import Callable
from concurrent.futures import Future
from typing import TYPE_CHECKING, Any, Generic

import zenoh

from cyborg.bus.field_check import field_problem, one_line
from cyborg.bus.typed import RequestT, ResponseT
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


class RequestError(ServiceError):
    """A request the service cannot take: ``field`` (``goal.x``, empty if unknown) and why.

    Raise it in a handler (or a check) to refuse a request without a traceback; the caller gets
    ``bad request: FIELD: REASON``. :meth:`ServiceClient.call` raises it for a request that does
    not fit the request type and for a server's refusal, with the service's name.
    """

    def __init__(self, field: str, reason: str, service: str = "") -> None:
        self.field, self.reason, self.service = field, one_line(reason), service
        self.detail = f"{field}: {self.reason}" if field else self.reason
        super().__init__(f"service {service}: bad request: {self.detail}" if service
                         else f"bad request: {self.detail}")


_BAD_REQUEST = "bad request: "
MAX_PENDING_REQUESTS = 64
"""Requests one server queues while its handler is busy; more are answered "busy" at once
(a flood of calls must not grow a node's memory without bound). ``server.max_pending`` changes
it for one server."""
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
        # by name: the endpoint serves whatever type its creator gave (Node checked a
        # ServiceType's classes against these when it named it)
        self.request_class = context.types.message_class(f"{service_type}_Request")
        self.response_class = context.types.message_class(f"{service_type}_Response")
        self._token = context.session.liveliness().declare_token(self.token_key)
        self._closed = False

    @property
    def closed(self) -> bool:
        """Whether this endpoint was destroyed (or its context closed under it)."""
        return self._closed

    def _undeclare(self) -> bool:
        if self._closed or self.context.closed:
            self._closed = True
            return False
        self._closed = True
        self._token.undeclare()
        return True


class Responder(Generic[ResponseT]):
    """Answers one request, now or later (from any thread), exactly once."""

    def __init__(self, server: ServiceServer[Any, ResponseT], query: zenoh.Query,
                 attachment: Attachment) -> None:
        self._server, self._query, self._attachment = server, query, attachment
        self._done = threading.Lock()

    @property
    def caller_gid(self) -> bytes:
        """The calling client's 16-byte GID, from the request's attachment.

        It says which client asked, e.g. to release what it set up once its liveliness token is
        gone.
        """
        return self._attachment.gid

    def reply(self, response: ResponseT) -> None:
        """Send ``response`` (from any thread); a second answer to the request is dropped.

        A response that does not fit the response type becomes an error reply naming the field
        (and an error in the server's log), sent at once.
        """
        server = self._server
        response_type = f"{server.service_type}_Response"
        if not isinstance(response, server.response_class):
            log.error("service %s: the handler returned %s, not %s", server.name,
                      type(response).__name__, response_type)
            self._send_error(f"bad response from the handler: it returned "
                             f"{type(response).__name__}, not {response_type}")
            return
        try:
            payload = server.context.types.serialize(response, response_type)
        except Exception as exc:
            problem = field_problem(server.context.types, response_type, response) \
                or f"{type(exc).__name__}: {exc}"
            log.error("service %s: the handler's response does not fit %s: %s", server.name,
                      response_type, one_line(problem))
            self._send_error(f"bad response from the handler: {problem}")
            return
        if not self._done.acquire(blocking=False):
            return
        reply = Attachment(self._attachment.sequence, time.time_ns(), self._attachment.gid)
        self._query.reply(self._query.key_expr, payload.obj, attachment=reply.encode())
        self._query.drop()

    def fail(self, error: BaseException) -> None:
        """Answer with an error instead of a response (from any thread).

        The caller gets ``bad request: ...`` for a :class:`RequestError`, else the exception's
        type and the first line of its message.
        """
        if isinstance(error, RequestError):
            self._send_error(_BAD_REQUEST + error.detail)
        else:
            self._send_error(f"{type(error).__name__}: {error}")

    def _send_error(self, text: str) -> None:
        if not self._done.acquire(blocking=False):
            return
        self._query.reply_err(one_line(text).encode())
        self._query.drop()


class ServiceServer(_ServiceEndpoint, Generic[RequestT, ResponseT]):
    """Serves requests with ``handler(request) -> response`` on the node's thread.

    With ``deferred=True`` the handler is ``handler(request, responder)`` and answers through
    ``responder.reply(response)`` whenever it is ready (an action's get_result does this).

    ``checks`` are called with each decoded request before the handler; one that raises
    :class:`RequestError` refuses the request (``server.checks.append(require_finite)``).
    """

    def __init__(self, node: Node, name: str, service_type: str,
                 handler: Callable[..., Any], *, deferred: bool = False) -> None:
        super().__init__(node, name, service_type, EntityKind.SERVICE_SERVER)
        self.handler, self.deferred = handler, deferred
        self.handled = 0
        self.checks: list[Callable[[RequestT], object]] = []
        self._traced: set[type] = set()  # exception types whose traceback was logged
        self.max_pending = MAX_PENDING_REQUESTS
        self._pending = 0  # requests queued for the handler, not yet started
        self._pending_lock = threading.Lock()
        self._queryable = self.context.session.declare_queryable(
            self.key, self._on_query, complete=True)

    def _on_query(self, query: zenoh.Query) -> None:
        payload = query.payload.to_bytes() if query.payload is not None else b""
        try:
            attachment = Attachment.decode(query.attachment.to_bytes()) if query.attachment \
                else Attachment(0, 0, bytes(16))
            request = self.context.types.deserialize(payload, f"{self.service_type}_Request")
        except Exception as exc:  # the request's type is checked here, before the handler
            self.context.drop(f"{self.name}: cannot decode request", one_line(str(exc)))
            query.reply_err(one_line(f"{_BAD_REQUEST}not a {self.service_type} request "
                                      f"({len(payload)} bytes): {exc}").encode())
            query.drop()
            return
        with self._pending_lock:
            busy = self._pending >= self.max_pending
            if not busy:
                self._pending += 1
        if busy:
            self.context.drop(f"{self.name}: busy", f"{self.max_pending} requests waiting")
            query.reply_err(one_line(f"service {self.name} is busy: {self.max_pending} "
                                      "requests are waiting; try again later").encode())
            query.drop()
            return
        self.node.callbacks.submit(self._handle, Responder(self, query, attachment), request)

    def _handle(self, responder: Responder[ResponseT], request: RequestT) -> None:
        with self._pending_lock:
            self._pending -= 1
        self.handled += 1
        try:
            for check in self.checks:
                check(request)
            if self.deferred:
                self.handler(request, responder)
            else:
                responder.reply(self.handler(request))
        except RequestError as exc:
            log.warning("service %s: bad request from client %s: %s", self.name,
                        responder.caller_gid.hex()[:12], exc.detail)
            responder.fail(exc)
        except Exception as exc:
            first = type(exc) not in self._traced
            self._traced.add(type(exc))
            log.error("service %s: the handler raised %s: %s%s", self.name, type(exc).__name__,
                      one_line(str(exc)), "" if first else " (traceback logged before)",
                      exc_info=first)
            responder.fail(exc)

    def destroy(self) -> None:
        """Withdraw the service from the bus; requests arriving later get no answer from it."""
        if self._undeclare():
            self._queryable.undeclare()


class ServiceClient(_ServiceEndpoint, Generic[RequestT, ResponseT]):
    """Calls a service: :meth:`call` blocks, :meth:`call_async` returns a Future."""

    def __init__(self, node: Node, name: str, service_type: str) -> None:
        super().__init__(node, name, service_type, EntityKind.SERVICE_CLIENT)
        self._sequence = itertools.count(1)

    def service_is_ready(self) -> bool:
        """Whether a server for this service is in the graph now."""
        return self.context.graph.count(self.name, EntityKind.SERVICE_SERVER) > 0

    def wait_for_service(self, timeout: float = 5.0) -> bool:
        """Whether a server for this service is in the graph within ``timeout`` seconds.

        Blocks the calling thread until it is or the time is up.
        """
        return self.context.graph.wait_for(lambda graph: self.service_is_ready(), timeout)

    def call(self, request: RequestT, timeout: float = 5.0) -> ResponseT:
        """Send ``request`` and return the response, blocking the calling thread for it.

        Raises :class:`ServiceError` on failure: :class:`RequestError` for a request that does
        not fit the request type (nothing is sent) or that the server refused,
        :class:`ServiceTimeoutError` without a reply within ``timeout`` seconds, TypeError for a
        request of another class.
        """
        if not isinstance(request, self.request_class):
            raise TypeError(f"call {self.name}: expected {self.service_type}_Request, "
                            f"got {type(request).__name__}")
        request_type = f"{self.service_type}_Request"
        try:
            payload = self.context.types.serialize(request, request_type)
        except Exception as exc:
            problem = field_problem(self.context.types, request_type, request)
            if problem is None:
                raise RequestError("", f"cannot send it ({type(exc).__name__}: {exc})",
                                   self.name) from exc
            field, _colon, reason = problem.partition(": ")
            raise RequestError(field, reason, self.name) from exc
        attachment = Attachment(next(self._sequence), time.time_ns(), self.gid)
        replies = self.context.session.get(
            self.key, payload=payload.obj, attachment=attachment.encode(),
            target=zenoh.QueryTarget.ALL_COMPLETE, consolidation=zenoh.ConsolidationMode.NONE,
            timeout=timeout)
        started = time.monotonic()
        for reply in replies:
            if reply.ok is not None:
                try:
                    response: ResponseT = self.context.types.deserialize(
                        reply.ok.payload.to_bytes(), f"{self.service_type}_Response")
                    return response
                except Exception as exc:
                    raise ServiceError(f"service {self.name}: cannot decode the response: "
                                       f"{one_line(str(exc))}") from exc
            if reply.err is not None:
                text = one_line(reply.err.payload.to_bytes().decode("utf-8", "replace"))
                if text == "Timeout":
                    break
                if text.startswith(_BAD_REQUEST):
                    raise RequestError("", text.removeprefix(_BAD_REQUEST), self.name)
                raise ServiceError(f"service {self.name} failed: {text}")
        if time.monotonic() - started >= timeout * 0.9:
            raise ServiceTimeoutError(f"service {self.name}: no reply within {timeout:g} s")
        raise ServiceError(f"service {self.name} ({self.service_type}) is not available; "
                           "is its server running? (`cyborg service list`)")

    def call_async(self, request: RequestT, timeout: float = 5.0) -> Future[ResponseT]:
        """Like :meth:`call`, on a worker thread; the Future holds the response or the error."""
        return self.context.calls.submit(self.call, request, timeout)

    def destroy(self) -> None:
        """Withdraw the client from the bus graph."""
        self._undeclare()
