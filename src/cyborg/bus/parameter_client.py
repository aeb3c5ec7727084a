"""Read and set another node's parameters through its ROS 2 parameter services."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from cyborg.bus.parameters import from_message, to_message

if TYPE_CHECKING:
    from cyborg.bus.node import Node


class ParameterError(RuntimeError):
    """A parameter could not be read or set; the message says which and why."""


class ParameterClient:
    """``client.list()``, ``client.get(names)``, ``client.set({name: value})`` on one node."""

    def __init__(self, node: Node, target: str, timeout: float = 5.0) -> None:
        self._types = node.types
        self.target, self.timeout = target.rstrip("/") or "/", timeout
        self._clients = {
            name: node.create_client(f"{self.target}/{name}",
                                     f"rcl_interfaces/srv/{service}")
            for name, service in (("list_parameters", "ListParameters"),
                                  ("get_parameters", "GetParameters"),
                                  ("set_parameters", "SetParameters"),
                                  ("describe_parameters", "DescribeParameters"))}

    def _call(self, name: str, **fields: Any) -> Any:
        client = self._clients[name]
        request = self._types.message_class(f"{client.service_type}_Request")(**fields)
        return client.call(request, self.timeout)

    def names(self) -> list[str]:
        return list(self._call("list_parameters", prefixes=[], depth=0).result.names)

    def get(self, names: list[str]) -> dict[str, Any]:
        """Values by name; a name the node does not have raises ParameterError."""
        values = self._call("get_parameters", names=names).values
        result = {name: from_message(value) for name, value in zip(names, values, strict=True)}
        missing = [name for name, value in result.items() if value is None]
        if missing:
            raise ParameterError(f"{self.target} has no parameter {', '.join(missing)}")
        return result

    def describe(self, names: list[str]) -> list[Any]:
        return list(self._call("describe_parameters", names=names).descriptors)

    def set(self, values: dict[str, Any]) -> None:
        """Set each parameter; ParameterError lists those the node refused, and why."""
        parameter = self._types.message_class("rcl_interfaces/msg/Parameter")
        try:
            request = [parameter(name=name, value=to_message(self._types, value))
                       for name, value in values.items()]
        except ValueError as exc:
            raise ParameterError(str(exc)) from exc
        results = self._call("set_parameters", parameters=request).results
        refused = [f"{name}: {result.reason}" for name, result in
                   zip(values, results, strict=True) if not result.successful]
        if refused:
            raise ParameterError(f"{self.target} refused " + "; ".join(refused))
