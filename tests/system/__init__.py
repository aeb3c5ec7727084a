"""Whole-system tests: the simulator, tree runner and monitor together."""
