"""Tests of cyborg.nav."""
