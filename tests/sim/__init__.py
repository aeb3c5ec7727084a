"""Tests of cyborg.sim."""
