"""Input and output ports: how a behavior3 v1 file wires a node to the blackboard.

A node class declares its ports in order, as the editor's node definition does::

    class Greet(Action):
        inputs = ("name", "greeting?")     # "?": optional
        outputs = ("said",)

        def tick(self) -> Status:
            text = f"{self.read('greeting', 'Hello')}, {self.read('name')}"
            self.write("said", text)
            return SUCCESS

and a tree file binds them **by position** to blackboard keys (``"input": ["visitor", ""],
"output": ["last_greeting"]``; ``""`` leaves a port unbound), in the style of
BehaviorTree.CPP's ports: the node reads and writes the keys the tree names, so one class
serves trees that keep their data under different names. A last port named ``"args..."``
takes any number of further keys (bound as ``args``, ``args.2``, ``args.3``, ...).
"""

from __future__ import annotations

from collections.abc import Sequence

OPTIONAL = "?"
REPEATED = "..."


def port_name(declared: str) -> str:
    """``"target?"`` -> ``"target"``; ``"args..."`` -> ``"args"``."""
    return declared.removesuffix(REPEATED).removesuffix(OPTIONAL)


def bind_ports(declared: Sequence[str], keys: Sequence[str],
               direction: str) -> tuple[dict[str, str], list[str], list[str]]:
    """Matches a file's ``keys`` to the ``declared`` ports by position.

    Returns port name -> key for every bound port, the errors (a required port left unbound)
    and the warnings (a key with no port to go to: ignored, as the editor's build drops it).
    ``direction`` is ``input`` or ``output`` (the file's field), for the sentences.
    """
    ports: dict[str, str] = {}
    problems: list[str] = []
    ignored: list[str] = []
    repeats = bool(declared) and declared[-1].endswith(REPEATED)
    for index, key in enumerate(keys):
        if index < len(declared):
            name = port_name(declared[index])
        elif repeats:
            name = f"{port_name(declared[-1])}.{index - len(declared) + 2}"
        elif not key:
            continue  # the editor writes [""] for a node without ports
        else:
            listing = ", ".join(repr(port) for port in declared) or "none"
            ignored.append(f"{direction} #{index + 1} ({key!r}) is ignored: the node has "
                           f"{len(declared)} {direction} port"
                           f"{'s' if len(declared) != 1 else ''} ({listing})")
            continue
        if key:
            ports[name] = key
    for index, port in enumerate(declared):
        required = not port.endswith((OPTIONAL, REPEATED))
        if required and (index >= len(keys) or not keys[index]):
            problems.append(f"{direction} port {port!r} is not bound to a blackboard key")
    return ports, problems, ignored
