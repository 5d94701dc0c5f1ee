"""Plates seen but unread: kept until read, their cells, and the zones from which they are read."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sim.navigation.spotted import SpottedParams, SpottedTags
from sim.perception.sighting import Sighting
from sim.perception.spotting import Spot
from tests.sim.navigation.test_routes import at, grid_of

# A plate on the north wall of a corridor (wall y 4.0-4.2), facing south (-y), at x = 10.
WALL = [(0.0, 20.0, 4.0, 4.2)]
PLATE = Spot(10.0, 4.0, -math.pi / 2, 6.0)


def test_a_plate_seen_stays_unread_until_read_and_is_kept_once():
    tags = SpottedTags()
    assert tags.update([], [PLATE]) and tags.version == 1
    assert not tags.update([], [Spot(10.05, 4.0, -math.pi / 2, 5.0)])  # the same plate, seen again
    assert len(tags.unread) == 1
    assert tags.update([Sighting(7, 10.0, 4.0, -math.pi / 2, 2.0)], [PLATE])  # read: no longer unread
    assert tags.unread == [] and tags.read == [(10.0, 4.0)]
    assert not tags.update([], [PLATE])  # seen again after reading: still read


def test_a_plates_reading_zone_lies_in_front_of_it_inside_the_reading_cone():
    grid = grid_of(WALL)
    tags = SpottedTags()
    tags.update([], [PLATE])
    zones = tags.zones(grid)
    assert at(grid, zones, 10.0, 2.0)  # square in front, 2 m out
    assert at(grid, zones, 10.8, 2.2)  # 24 degrees off its normal
    assert not at(grid, zones, 10.0, 3.5)  # too near for the camera
    assert not at(grid, zones, 12.0, 3.0)  # 63 degrees off: edge-on
    assert not at(grid, zones, 10.0, 0.5)  # past 3 m
    assert not at(grid, zones, 10.0, 5.0)  # behind its wall
    assert not np.any(zones & grid.occupied_mask())


@pytest.mark.parametrize("plate_wall_m", [0.5, 10.0])
def test_a_zone_is_worth_the_belief_on_its_plate_times_the_wall_it_stands_for(plate_wall_m):
    grid = grid_of(WALL)
    tags = SpottedTags(SpottedParams(plate_wall_m=plate_wall_m))
    tags.update([], [PLATE])
    mass = np.zeros(grid.shape)
    plate = tags.tag_cells(grid)
    mass[plate] = 0.5 / plate.sum()
    mass[grid.world_to_cell(np.array([3.0, 4.1]))[0][0], grid.world_to_cell(np.array([3.0, 4.1]))[0][1]] = 0.5
    values = tags.zone_values(grid, mass)
    worth = plate_wall_m / (2 * tags.params.tag_radius_m)  # a plate 0.5 m wide stands for plate_wall_m of wall
    assert at(grid, values, 10.0, 2.0) == pytest.approx(0.5 * worth)
    assert at(grid, values, 3.0, 2.0) == 0.0
    assert 2 <= plate.sum() <= 30  # a disc of 0.25 m on 0.1 m cells


def test_standing_in_a_zone_without_reading_the_plate_gives_it_up():
    grid = grid_of(WALL)
    tags = SpottedTags()
    tags.update([], [PLATE])
    assert not tags.give_up_at(grid, np.array([3.0, 2.0]))  # not in its zone
    assert tags.give_up_at(grid, np.array([10.0, 2.0]))
    assert tags.unread == [] and tags.read_cells(grid).any()
    assert not tags.zones(grid).any()


def test_parameters_keep_the_zone_inside_the_reading_rule():
    p = SpottedParams()
    assert p.zone_far_m < 4.0 and p.zone_half_angle_deg < 45.0 and p.zone_near_m >= 1.0
    assert p.sweep_range_m < 8.0 and p.sweep_cone_deg < 75.0


def test_a_path_through_the_door_beside_an_unread_plate_stops_in_front_of_it_first():
    tags = SpottedTags()
    tags.update([], [PLATE])
    into_door = np.array([[6.0, 1.0], [9.0, 3.5], [9.0, 6.0]])  # diagonally up to the door at x = 9, then through
    found = tags.door_stop(into_door)
    assert found is not None
    plate, stop = found
    assert plate == PLATE
    assert stop == pytest.approx([10.0, 4.0 - SpottedParams().read_at_m])  # square in front, inside its zone
    assert tags.door_stop(into_door[::-1]) is None  # leaving through the door faces the plate: read on the way
    along = np.array([[2.0, 2.0], [18.0, 2.0]])
    assert tags.door_stop(along) is None  # walking the corridor passes it (its zone does the rest)
    far_door = np.array([[6.0, 1.0], [14.0, 3.5], [14.0, 6.0]])
    assert tags.door_stop(far_door) is None  # a door 4 m along the wall is another room's
    tags.update([Sighting(7, 10.0, 4.0, -math.pi / 2, 2.0)], [])
    assert tags.door_stop(into_door) is None  # read: nothing to stop for
