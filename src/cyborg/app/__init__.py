"""The ``cyborg`` command line: the one place where the packages are wired together.

The package exports nothing itself: import the modules.
"""

__all__: list[str] = []
