"""Tests of cyborg.bus."""
