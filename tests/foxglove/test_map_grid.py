"""Rasterising a map for Foxglove: bounded cells, the map's resolution, bad numbers left out."""

from __future__ import annotations

import numpy as np
import pytest

from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import MapGeometry
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.foxglove.map_grid import MAX_CELLS, grid_resolution, occupancy_grid
from cyborg.nav.arnl_map import read_map
from cyborg.nav.map_message import map_geometry
from tests.conftest import shared_dir


def geometry(lines: list[float], points: list[float] | None = None) -> MapGeometry:
    return MapGeometry(header=Header(stamp=Time(sec=0, nanosec=0), frame_id="map"),
                       source="test.map", hash="", resolution=0.02,
                       lines=np.array(lines, np.float32),
                       points=np.array(points or [], np.float32), objects=[])


def test_the_resolution_is_held_between_5_and_10_cm_and_coarsened_for_huge_maps() -> None:
    assert grid_resolution(0.02, 10, 10) == pytest.approx(0.05)
    assert grid_resolution(0.08, 10, 10) == pytest.approx(0.08)
    assert grid_resolution(0.5, 10, 10) == pytest.approx(0.1)
    huge = grid_resolution(0.05, 5000, 5000)
    assert (5000 / huge + 2) ** 2 <= MAX_CELLS
    with pytest.raises(ValueError, match="map_geometry: the map spans"):
        grid_resolution(0.05, float("inf"), 1)


def test_a_huge_map_from_the_bus_costs_a_bounded_grid() -> None:
    grid = occupancy_grid(geometry([-1e6, 0, 1e6, 0]))
    assert grid.info.width * grid.info.height <= MAX_CELLS
    assert (np.asarray(grid.data) == 100).any()


def test_coordinates_that_are_not_numbers_are_left_out() -> None:
    grid = occupancy_grid(geometry([0, 0, 1, 0, float("nan"), 0, 1e9, 1], [float("inf"), 2]))
    assert grid.info.width * grid.info.height < 10_000  # drawn around the one good wall
    assert (np.asarray(grid.data) == 100).sum() > 0


def test_the_largest_shared_map_draws_its_walls() -> None:
    message = map_geometry(read_map(shared_dir() / "maps" / "columbia.map"))
    grid = occupancy_grid(message)
    assert grid.info.resolution == pytest.approx(0.05)
    occupied = int((np.asarray(grid.data) == 100).sum())
    assert occupied > len(message.points) // 2 // 10  # scanned points land in cells
