"""The ``cyborg`` command line: the one place where the packages are wired together."""
