"""What lies behind each frontier: belief mass gathered by the frontier its route enters through."""

from __future__ import annotations

import numpy as np
import pytest

from sim.navigation.gateways import GuideParams, frontier_values
from tests.sim.navigation.test_routes import at, grid_of

# A corridor along y 0-2 under a wall with a 1 m door at x 5-6 into a closed room (x 0-8, y 2.2-12) and a
# 2 m opening at x 15-17 onto a hall (x 8.2-20, y 2.2-12). The robot stands at (2, 1) and has looked at the
# corridor up to x = 8.
WALLS = [(0.0, 5.0, 2.0, 2.2), (6.0, 15.0, 2.0, 2.2), (17.0, 20.0, 2.0, 2.2), (8.0, 8.2, 2.2, 12.0)]
ROBOT = np.array([2.0, 1.0])
ALL_BEHIND = GuideParams(look_ahead_m=())  # a frontier worth all the mass behind it, however far


def looked_at(grid) -> np.ndarray:
    xy = grid.cell_to_world(np.argwhere(np.ones(grid.shape, dtype=bool))).reshape(*grid.shape, 2)
    return (xy[..., 0] < 8.0) & (xy[..., 1] < 2.0)


def region(grid, x0: float, x1: float, y0: float, y1: float) -> np.ndarray:
    xy = grid.cell_to_world(np.argwhere(np.ones(grid.shape, dtype=bool))).reshape(*grid.shape, 2)
    return (xy[..., 0] >= x0) & (xy[..., 0] < x1) & (xy[..., 1] >= y0) & (xy[..., 1] < y1)


def test_a_corridors_open_end_carries_all_it_leads_to_and_a_doorway_only_its_room():
    grid = grid_of(WALLS)
    looked = looked_at(grid)
    mass = np.where(looked, 0.0, 1.0)
    values = frontier_values(grid, mass, looked, ROBOT, ALL_BEHIND)
    room = float(mass[region(grid, 0.0, 8.0, 2.2, 12.0)].sum())
    beyond = float(mass.sum()) - room
    door, corridor_end = at(grid, values, 5.5, 1.6), at(grid, values, 8.0, 1.0)
    assert door == pytest.approx(room, rel=0.15)
    assert corridor_end == pytest.approx(beyond, rel=0.15)
    assert corridor_end > 1.5 * door


def test_mass_in_the_room_alone_makes_only_its_doorway_worth_going_to():
    grid = grid_of(WALLS)
    looked = looked_at(grid)
    mass = np.where(region(grid, 1.0, 7.0, 4.0, 11.0), 1.0, 0.0)
    values = frontier_values(grid, mass, looked, ROBOT, ALL_BEHIND)
    assert at(grid, values, 5.5, 1.6) == pytest.approx(float(mass.sum()), rel=1e-6)
    assert at(grid, values, 8.0, 1.0) == pytest.approx(0.0, abs=1e-9)


def test_mass_on_a_wall_counts_on_the_side_it_faces():
    """The room's east wall (x 8-8.2) has a face in the room, reached through the door, and one on the hall,
    reached through the far opening: each face's mass goes to its own frontier."""
    grid = grid_of(WALLS)
    looked = looked_at(grid)
    for face, through in (((8.0, 8.1), (5.5, 1.6)), ((8.1, 8.2), (8.0, 1.0))):
        mass = np.where(region(grid, *face, 3.0, 6.0), 1.0, 0.0)
        values = frontier_values(grid, mass, looked, ROBOT, ALL_BEHIND)
        other = (8.0, 1.0) if through == (5.5, 1.6) else (5.5, 1.6)
        assert at(grid, values, *through) == pytest.approx(float(mass.sum()), rel=1e-6)
        assert at(grid, values, *other) == pytest.approx(0.0, abs=1e-9)


def test_nothing_reachable_is_worth_nothing():
    grid = grid_of(WALLS)
    looked = looked_at(grid)
    values = frontier_values(grid, np.zeros(grid.shape), looked, ROBOT)
    assert float(values.max()) == 0.0


def test_a_frontier_is_worth_the_best_rate_of_a_walk_past_it():
    """A small mass just inside the room's door against twice as much at the hall's far corner: by all the
    mass behind, the corridor's end is worth twice the door; by the best rate of belief per metre a walk past
    each gives, the door costs fewer metres per unit of belief, since the hall's mass lies some 20 m past its
    frontier."""
    grid = grid_of(WALLS)
    looked = looked_at(grid)
    near_room = region(grid, 5.0, 6.0, 2.2, 3.2)
    far_hall = region(grid, 18.0, 20.0, 9.0, 12.0)
    mass = np.where(near_room, 1.0 / near_room.sum(), 0.0) + np.where(far_hall, 2.0 / far_hall.sum(), 0.0)
    (door, door_path), (end, end_path) = ((5.5, 1.6), 3.5), ((8.0, 1.0), 6.0)  # m by route from the robot
    offset = GuideParams().offset_m
    raw = frontier_values(grid, mass, looked, ROBOT, ALL_BEHIND)
    assert at(grid, raw, *end) > 1.5 * at(grid, raw, *door)
    values = frontier_values(grid, mass, looked, ROBOT)
    lead = door_path + offset
    assert lead / (lead + 3.0) - 0.05 < at(grid, values, *door) <= 1.0  # all of it within the first 3 m past
    assert at(grid, values, *end) == pytest.approx(2.0 * (end_path + offset) / (end_path + offset + 24.0), rel=0.1)
    assert (door_path + offset) / at(grid, values, *door) < (end_path + offset) / at(grid, values, *end)


def test_mass_at_the_gateway_is_worth_all_of_it_and_never_more():
    grid = grid_of(WALLS)
    looked = looked_at(grid)
    mass = np.where(region(grid, 5.0, 6.0, 1.8, 2.1), 1.0, 0.0)  # in the doorway itself, where it is first unlooked
    values = frontier_values(grid, mass, looked, ROBOT)
    raw = frontier_values(grid, mass, looked, ROBOT, ALL_BEHIND)
    assert at(grid, values, 5.5, 1.6) == pytest.approx(float(mass.sum()), rel=1e-6)
    assert (values <= raw + 1e-9).all()
