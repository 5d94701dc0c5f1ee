"""Occupancy grid updates from synthetic scans."""

import math

import numpy as np
import pytest

from sim.mapping.occupancy import OccupancyGrid, OccupancyParams, mapped_plan
from sim.perception.laser import LaserParams, grid_caster, laser_angles, scan

SMALL = OccupancyParams(resolution_m=0.1, bounds=(-2.0, 6.0, -3.0, 3.0))


def test_cells_and_world_points_round_trip() -> None:
    grid = OccupancyGrid(SMALL)
    assert grid.shape == (60, 80)
    assert grid.extent == pytest.approx((-2.0, 6.0, -3.0, 3.0))
    rc = grid.world_to_cell(np.array([[-1.95, 2.95], [5.95, -2.95]]))
    assert rc.tolist() == [[0, 0], [59, 79]]  # row 0 is the top (largest y)
    back = grid.cell_to_world(rc)
    assert back == pytest.approx(np.array([[-1.95, 2.95], [5.95, -2.95]]))
    assert grid.unknown_mask().all()
    assert grid.explored_centre() is None


def test_beam_marks_free_cells_and_occupied_endpoint_only() -> None:
    grid = OccupancyGrid(SMALL)
    grid.integrate((0.05, 0.05, 0.0), np.array([0.0]), np.array([2.0]), max_range=8.0)
    row = grid.world_to_cell([0.05, 0.05])[0, 0]
    start_col = grid.world_to_cell([0.05, 0.05])[0, 1]
    end_col = grid.world_to_cell([2.05, 0.05])[0, 1]
    free, occupied, unknown = grid.free_mask(), grid.occupied_mask(), grid.unknown_mask()
    assert free[row, start_col:end_col].all()
    assert occupied[row, end_col]
    assert free.sum() == end_col - start_col
    assert occupied.sum() == 1
    assert unknown.sum() == grid.log_odds.size - free.sum() - 1


def test_beam_without_hit_marks_no_obstacle() -> None:
    grid = OccupancyGrid(SMALL)
    grid.integrate((0.05, 0.05, math.pi), np.array([0.0]), np.array([np.inf]), max_range=1.0)
    assert not grid.occupied_mask().any()
    xs = grid.cell_to_world(np.argwhere(grid.free_mask()))[:, 0]
    assert xs.min() == pytest.approx(-0.95) and xs.max() == pytest.approx(0.05)


def test_beams_shorter_than_min_range_are_ignored() -> None:
    grid = OccupancyGrid(SMALL)
    grid.integrate((0.05, 0.05, 0.0), np.array([0.0, 1.0]), np.array([0.0, 1.5]), max_range=8.0, min_range=0.05)
    assert grid.occupied_mask().sum() == 1
    assert not grid.occupied_mask()[tuple(grid.world_to_cell([0.05, 0.05])[0])]


def square_room(centre: tuple[float, float], half: float, res: float = 0.05) -> tuple[np.ndarray, float, tuple]:
    """A 12 m x 12 m image (origin (-6, -6)) holding a square room with 0.1 m walls."""
    n = int(12.0 / res)
    centres = (np.arange(n) + 0.5) * res - 6.0
    x = centres[None, :]
    y = centres[::-1, None]
    dx, dy = np.abs(x - centre[0]), np.abs(y - centre[1])
    inside_outer = (dx <= half + 0.1) & (dy <= half + 0.1)
    inside_inner = (dx < half) & (dy < half)
    return inside_outer & ~inside_inner, res, (-6.0, -6.0)


def test_explored_centre_is_the_centroid_of_the_free_region() -> None:
    room_centre = (1.0, -0.5)
    caster = grid_caster(*square_room(room_centre, 2.0))
    grid = OccupancyGrid(OccupancyParams(resolution_m=0.1, bounds=(-6.0, 6.0, -6.0, 6.0)))
    params = LaserParams(fov_deg=360, n_beams=720)
    for pose in [(0.0, -1.5, 0.3), (2.2, 0.8, 2.0), (1.0, -0.5, -1.0)]:
        grid.integrate(pose, laser_angles(params), scan(pose, caster, params), params.max_range_m)
    centre = grid.explored_centre()
    assert centre is not None
    assert centre == pytest.approx(room_centre, abs=0.1)
    free_xy = grid.cell_to_world(np.argwhere(grid.free_mask()))
    assert np.all(np.abs(free_xy - room_centre) < 2.0)  # nothing outside the walls is marked free
    # The walls themselves are mapped as occupied all around.
    occupied_xy = grid.cell_to_world(np.argwhere(grid.occupied_mask()))
    assert np.all(np.max(np.abs(occupied_xy - room_centre), axis=1) > 1.85)
    assert len(occupied_xy) > 4 * 35


def test_explored_centre_of_a_known_rectangle() -> None:
    grid = OccupancyGrid(SMALL)
    rc = grid.world_to_cell(np.array([[1.05, 1.95], [2.95, -0.95]]))  # corner cells of x 1..3, y -1..2
    grid.log_odds[rc[0, 0]:rc[1, 0] + 1, rc[0, 1]:rc[1, 1] + 1] = -1.0
    assert grid.free_mask().sum() == 20 * 30
    assert grid.explored_centre() == pytest.approx((2.0, 0.5), abs=1e-9)


def test_repeated_scans_keep_walls_and_clamp() -> None:
    occupied = np.zeros((60, 80), dtype=bool)
    occupied[:, 50] = True  # x in [3.0, 3.1)
    caster = grid_caster(occupied, 0.1, (-2.0, -3.0))
    grid = OccupancyGrid(SMALL)
    params = LaserParams()
    for k in range(30):
        pose = (0.0, 0.1 * (k % 5), 0.05 * k)
        grid.integrate(pose, laser_angles(params), scan(pose, caster, params), params.max_range_m)
    lo, hi = SMALL.clamp
    assert grid.log_odds.min() >= lo and grid.log_odds.max() <= hi
    wall = grid.occupied_mask()[10:50, 50]
    assert wall.mean() > 0.9
    assert not grid.occupied_mask()[:, :50].any()


def test_copy_is_independent_and_image_uses_map_greys() -> None:
    grid = OccupancyGrid(SMALL)
    grid.integrate((0.05, 0.05, 0.0), np.array([0.0]), np.array([1.0]), max_range=8.0)
    twin = grid.copy()
    twin.log_odds[:] = 0
    assert grid.occupied_mask().sum() == 1
    image = grid.to_image()
    assert image.dtype == np.uint8 and image.shape == grid.shape
    assert set(np.unique(image)) == {0, 205, 254}


def test_bad_inputs_are_named() -> None:
    grid = OccupancyGrid(SMALL)
    with pytest.raises(ValueError, match="pose"):
        grid.integrate((np.nan, 0.0, 0.0), np.zeros(1), np.ones(1), 8.0)
    with pytest.raises(ValueError, match="ranges"):
        grid.integrate((0.0, 0.0, 0.0), np.zeros(1), np.array([np.nan]), 8.0)
    with pytest.raises(ValueError, match="angles"):
        grid.integrate((0.0, 0.0, 0.0), np.zeros(2), np.ones(1), 8.0)
    with pytest.raises(ValueError, match="bounds"):
        OccupancyParams(bounds=(1.0, 0.0, 0.0, 1.0))


def test_occupied_cells_reads_the_mask_at_cells_and_off_the_grid_says_no() -> None:
    grid = OccupancyGrid(OccupancyParams(bounds=(0.0, 1.0, 0.0, 1.0)))
    grid.log_odds[3, 4] = grid.params.clamp[1]
    rc = np.array([[3, 4], [3, 5], [-1, 4], [3, grid.shape[1]]])
    np.testing.assert_array_equal(grid.occupied_cells(rc), [True, False, False, False])
    every = np.argwhere(np.ones(grid.shape, dtype=bool))
    np.testing.assert_array_equal(grid.occupied_cells(every).reshape(grid.shape), grid.occupied_mask())


def test_a_plan_mapped_whole_maps_a_wall_thinner_than_a_cell_and_leaves_the_floor_free():
    from sim.world.data import Floorplan

    occupied = np.zeros((100, 100), dtype=bool)  # 2 m x 2 m at 2 cm a pixel
    occupied[:, 50] = True  # one pixel thick, at x = 1.00 .. 1.02 m
    grid = mapped_plan(Floorplan(occupied, 0.02, (0.0, 0.0)), resolution_m=0.1)
    assert grid.shape == (20, 20)
    wall = grid.occupied_mask()
    assert wall.sum() == 20 and wall[:, grid.world_to_cell(np.array([[1.01, 1.0]]))[0, 1]].all()
    assert grid.free_mask().sum() == 20 * 19
