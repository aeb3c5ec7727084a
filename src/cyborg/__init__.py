"""cyborg: a control stack for the NTNU Cyborg, a Pioneer LX mobile robot.

Sub-packages, in dependency order:

* :mod:`cyborg.bt` — the behaviour-tree engine (pure Python, no I/O);
* :mod:`cyborg.app` — the ``cyborg`` command line, which wires everything together.
"""

__version__ = "0.1.0"
