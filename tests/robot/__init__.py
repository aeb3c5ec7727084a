"""Tests of cyborg.robot."""
