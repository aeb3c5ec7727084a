"""Tests of cyborg.monitor."""
