"""Tests of cyborg.app."""
