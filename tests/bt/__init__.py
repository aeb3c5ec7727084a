"""Tests of cyborg.bt."""
