"""Tests of cyborg.interfaces."""
