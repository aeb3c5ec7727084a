"""Tests of cyborg.runner."""
