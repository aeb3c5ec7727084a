"""Read and set another node's parameters through its ROS 2 parameter services."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

from cyborg.bus.msgs.rcl_interfaces.msg import Parameter, ParameterDescriptor
from cyborg.bus.msgs.rcl_interfaces.srv import (
    DescribeParameters,
    GetParameters,
    ListParameters,
    SetParameters,
)
from cyborg.bus.parameters import from_message, to_message

if TYPE_CHECKING:
    from cyborg.bus.node import Node


class ParameterError(RuntimeError):
    """A parameter could not be read or set; the message says which and why."""


class ParameterClient:
    """``client.names()``, ``client.get(names)``, ``client.set({name: value})`` on one node.

    Each call blocks the calling thread for the service's reply, at most ``timeout`` seconds
    (then :class:`~cyborg.bus.services.ServiceError`, as for any service call).
    """

    def __init__(self, node: Node, target: str, timeout: float = 5.0) -> None:
        self.target, self.timeout = target.rstrip("/") or "/", timeout
        self._list = node.create_client(f"{self.target}/list_parameters", ListParameters)
        self._get = node.create_client(f"{self.target}/get_parameters", GetParameters)
        self._set = node.create_client(f"{self.target}/set_parameters", SetParameters)
        self._describe = node.create_client(f"{self.target}/describe_parameters",
                                            DescribeParameters)

    def wait_for_service(self, timeout: float = 5.0) -> bool:
        """Whether the node's parameter services are on the bus within ``timeout`` seconds.

        Blocks the calling thread until all of them are in the graph or the time (wall
        clock) is up.
        """
        deadline = time.monotonic() + timeout
        return all(client.wait_for_service(max(deadline - time.monotonic(), 0.0))
                   for client in (self._list, self._get, self._set, self._describe))

    def names(self) -> list[str]:
        """The names of every parameter the node has declared."""
        request = ListParameters.Request(prefixes=[], depth=0)
        return list(self._list.call(request, self.timeout).result.names)

    def get(self, names: list[str]) -> dict[str, Any]:
        """Values by name; a name the node does not have raises ParameterError."""
        values = self._get.call(GetParameters.Request(names=names), self.timeout).values
        result = {name: from_message(value) for name, value in zip(names, values, strict=True)}
        missing = [name for name, value in result.items() if value is None]
        if missing:
            raise ParameterError(f"{self.target} has no parameter {', '.join(missing)}")
        return result

    def describe(self, names: list[str]) -> list[ParameterDescriptor]:
        """The descriptors of ``names``: type, description, read-only flag and range."""
        request = DescribeParameters.Request(names=names)
        return list(self._describe.call(request, self.timeout).descriptors)

    def set(self, values: dict[str, Any]) -> None:
        """Set each parameter; ParameterError lists those the node refused, and why."""
        try:
            parameters = [Parameter(name=name, value=to_message(value))
                          for name, value in values.items()]
        except ValueError as exc:
            raise ParameterError(str(exc)) from exc
        request = SetParameters.Request(parameters=parameters)
        results = self._set.call(request, self.timeout).results
        refused = [f"{name}: {result.reason}" for name, result in
                   zip(values, results, strict=True) if not result.successful]
        if refused:
            raise ParameterError(f"{self.target} refused " + "; ".join(refused))
