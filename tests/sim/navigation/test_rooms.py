"""Rooms behind doors labelled with another area's place (sim.navigation.rooms)."""

import math

import numpy as np

from sim.mapping.occupancy import OccupancyGrid, OccupancyParams
from sim.navigation.rooms import RoomParams, behind_door, other_rooms_likelihood


def plan(door_m: float = 1.0, room_mapped: bool = True) -> OccupancyGrid:
    """16 m x 12 m: a corridor (y 0-2 m) under a wall at y = 2.0-2.2 m with a gap ``door_m`` wide centred at
    x = 8 m; above it a room x 4-12 m, y 2.2-7 m (walls round it), mapped or unseen; unseen beyond."""
    grid = OccupancyGrid(OccupancyParams(resolution_m=0.1, bounds=(0.0, 16.0, 0.0, 12.0)))
    xy = grid.cell_to_world(np.argwhere(np.ones(grid.shape, dtype=bool)))
    cells = grid.world_to_cell(xy)
    x, y = xy[:, 0], xy[:, 1]
    gap = np.abs(x - 8.0) < door_m / 2
    corridor = y < 2.0
    wall = (y >= 2.0) & (y < 2.2) & ~gap
    doorway = (y >= 2.0) & (y < 2.2) & gap
    room = (x > 4.2) & (x < 11.8) & (y >= 2.2) & (y < 6.8)
    room_walls = (((np.abs(x - 4.1) < 0.1) | (np.abs(x - 11.9) < 0.1)) & (y >= 2.0) & (y < 7.0)) | \
        ((np.abs(y - 6.9) < 0.1) & (x >= 4.0) & (x < 12.0))
    grid.log_odds[cells[corridor | doorway, 0], cells[corridor | doorway, 1]] = -2.0
    grid.log_odds[cells[wall, 0], cells[wall, 1]] = 3.0
    if room_mapped:
        grid.log_odds[cells[room, 0], cells[room, 1]] = -2.0
        grid.log_odds[cells[room_walls, 0], cells[room_walls, 1]] = 3.0
    return grid


LABEL = ((8.85, 1.98), -math.pi / 2)  # beside the door, on the corridor face, facing the corridor (south)


def at(grid: OccupancyGrid, xy: tuple[float, float]) -> tuple[int, int]:
    return tuple(grid.world_to_cell(np.array(xy))[0])


def test_the_room_behind_a_labelled_door_is_found_and_nothing_else():
    grid = plan()
    likely = other_rooms_likelihood(grid, [LABEL])
    assert likely is not None
    low = RoomParams().other_suite_prob
    assert likely[at(grid, (8.0, 5.0))] == low  # the room's middle
    assert likely[at(grid, (4.4, 6.6))] == low  # its far corner
    assert likely[at(grid, (8.0, 1.0))] == 1.0  # the corridor in front
    assert likely[at(grid, (2.0, 5.0))] == 1.0  # beyond the room's west wall
    assert likely[at(grid, (8.0, 9.0))] == 1.0  # beyond its north wall


def test_unseen_room_behind_a_mapped_door_counts_out_to_the_reach():
    grid = plan(room_mapped=False)
    room = behind_door(grid, *LABEL, np.full(grid.shape, np.inf), grid.free_mask())
    assert room is not None
    assert room[at(grid, (8.0, 5.0))] and room[at(grid, (13.0, 4.0))]  # unseen: as far as the reach
    assert not room[at(grid, (8.0, 1.0))] and not room[at(grid, (8.0, 11.5))]  # the corridor; past the reach


def test_no_doorway_no_room():
    """A label on a plain wall, or beside a gap as wide as a corridor's mouth, says nothing of what is behind."""
    assert other_rooms_likelihood(plan(door_m=0.0), [LABEL]) is None
    assert other_rooms_likelihood(plan(door_m=2.4), [LABEL]) is None
    assert other_rooms_likelihood(plan(), []) is None
