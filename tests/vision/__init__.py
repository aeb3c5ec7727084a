"""Tests of cyborg.vision."""
