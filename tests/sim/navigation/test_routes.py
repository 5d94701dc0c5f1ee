"""Route evidence: arrows along the first leg of the route, and labels on the side a door is approached from."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sim.mapping.occupancy import OccupancyGrid, OccupancyParams, mapped_plan
from sim.navigation.routes import (
    Arrow,
    PathSearches,
    RouteParams,
    door_depth_weight,
    passed_likelihood,
    path_sums,
    route_likelihood,
    walls_take_front,
)


def grid_of(walls: list[tuple[float, float, float, float]], size: tuple[float, float] = (20.0, 12.0)
            ) -> OccupancyGrid:
    """A grid mapped free everywhere but the given wall boxes (x0, x1, y0, y1 in m), which are mapped occupied."""
    grid = OccupancyGrid(OccupancyParams(resolution_m=0.1, bounds=(0.0, size[0], 0.0, size[1])))
    grid.log_odds[:] = -2.0
    xy = grid.cell_to_world(np.argwhere(np.ones(grid.shape, dtype=bool)))
    cells = grid.world_to_cell(xy)
    for x0, x1, y0, y1 in walls:
        inside = (xy[:, 0] >= x0) & (xy[:, 0] < x1) & (xy[:, 1] >= y0) & (xy[:, 1] < y1)
        grid.log_odds[cells[inside, 0], cells[inside, 1]] = 3.0
    return grid


def at(grid: OccupancyGrid, field: np.ndarray, x: float, y: float) -> float:
    r, c = grid.world_to_cell(np.array([x, y]))[0]
    return float(field[r, c])


def test_an_arrow_favours_what_lies_along_its_route_and_never_rules_out():
    grid = grid_of([])
    east = Arrow(sign_xy=(10.0, 1.0), facing=math.pi / 2, direction=0.0, wrong_prob=0.1)
    likelihood = route_likelihood(grid, [east])
    assert likelihood is not None and likelihood.shape == grid.shape
    assert at(grid, likelihood, 17.0, 2.0) == pytest.approx(1.0, abs=0.05)  # ahead along the arrow
    assert at(grid, likelihood, 3.0, 2.0) < 0.15  # behind it: only the chance the arrow is wrong
    assert float(likelihood.min()) >= 0.1 - 1e-9
    assert route_likelihood(grid, []) is None


def test_an_arrow_holds_its_first_leg_to_the_signage_conventions_45_degrees():
    """Open floor: the route to a cell sets off straight at it from the reader, 1 m in front of the sign."""
    grid = grid_of([])
    east = Arrow(sign_xy=(10.0, 5.0), facing=math.pi / 2, direction=0.0, wrong_prob=0.1)
    reader = np.array([10.0, 6.0])
    likelihood = route_likelihood(grid, [east])
    for degrees in (0.0, 20.0, 35.0, -35.0):
        cell = reader + 5.0 * np.array([math.cos(math.radians(degrees)), math.sin(math.radians(degrees))])
        assert at(grid, likelihood, *cell) == pytest.approx(1.0)
    for degrees in (80.0, 120.0, 180.0, -100.0):  # off by more than the tolerance and the grid's zig-zag
        cell = reader + 5.0 * np.array([math.cos(math.radians(degrees)), math.sin(math.radians(degrees))])
        assert at(grid, likelihood, *cell) < 0.3


def test_route_likelihood_follows_a_corridor_round_its_corner():
    """A wall north of the sign with a gap at its east end: an arrow east leads to the room north of the wall,
    while a straight-line cone would have called it off the route only by the angle."""
    wall = (0.0, 16.0, 4.0, 4.2)  # the gap is x 16 .. 20
    grid = grid_of([wall])
    east = Arrow(sign_xy=(4.0, 1.0), facing=math.pi / 2, direction=0.0, wrong_prob=0.1)
    west = Arrow(sign_xy=(4.0, 1.0), facing=math.pi / 2, direction=math.pi, wrong_prob=0.1)
    north_room = (2.0, 8.0)  # reached only round the east end of the wall
    assert at(grid, route_likelihood(grid, [east]), *north_room) > 0.9
    assert at(grid, route_likelihood(grid, [west]), *north_room) < 0.15


def test_a_fingerpost_points_through_the_wall_at_its_place_and_a_share_of_it_mixes_the_two_readings():
    """The corridor round its corner again: read as a fingerpost (``bearing_share`` 1) the arrow west points at
    the room straight across the wall's west end, and the arrow east no longer leads round the corner to it;
    ``bearing_share`` 0 is the route reading itself, and a half share lies between the two."""
    grid = grid_of([(0.0, 16.0, 4.0, 4.2)])
    west = Arrow(sign_xy=(4.0, 1.0), facing=math.pi / 2, direction=math.pi * 0.75, wrong_prob=0.1)
    north_west_room = (1.0, 6.0)  # 3 m west and 4 m north of the reader, behind the wall
    route = route_likelihood(grid, [west])
    assert np.array_equal(route_likelihood(grid, [west], bearing_share=0.0), route)
    post = route_likelihood(grid, [west], bearing_share=1.0)
    half = route_likelihood(grid, [west], bearing_share=0.5)
    assert at(grid, route, *north_west_room) < 0.3 < 0.9 < at(grid, post, *north_west_room)
    assert at(grid, route, *north_west_room) < at(grid, half, *north_west_room) < at(grid, post, *north_west_room)
    east = Arrow(sign_xy=(4.0, 1.0), facing=math.pi / 2, direction=0.0, wrong_prob=0.1)
    assert at(grid, route_likelihood(grid, [east], bearing_share=1.0), 2.0, 8.0) < 0.15


def test_a_room_behind_a_door_weighs_less_than_the_corridor_it_opens_on():
    """A 2 m corridor (y 0 .. 2) and a room above it (y 2.2 .. 8) entered by a 1 m door at x 9.5 .. 10.5."""
    walls = [(0.0, 9.5, 2.0, 2.2), (10.5, 20.0, 2.0, 2.2)]
    grid = grid_of(walls)
    params = RouteParams()
    weight = door_depth_weight(grid, np.array([2.0, 1.0]), params)
    corridor_face, room_far_wall = (15.0, 1.9), (15.0, 7.0)
    assert at(grid, weight, *corridor_face) == pytest.approx(1.0)
    assert at(grid, weight, *room_far_wall) == pytest.approx(params.room_weight, rel=0.5)
    wide = grid_of([(0.0, 8.0, 2.0, 2.2), (12.0, 20.0, 2.0, 2.2)])  # a 4 m opening: no door, one space
    assert at(wide, door_depth_weight(wide, np.array([2.0, 1.0]), params), *room_far_wall) == pytest.approx(1.0)


def test_kept_path_searches_give_the_same_evidence_and_run_again_only_on_a_changed_map():
    walls = [(0.0, 9.5, 2.0, 2.2), (10.5, 20.0, 2.0, 2.2)]
    grid = grid_of(walls)
    east = Arrow(sign_xy=(4.0, 1.0), facing=math.pi / 2, direction=0.0, wrong_prob=0.1)
    searches = PathSearches()
    start = np.array([2.0, 1.0])
    depth, route = door_depth_weight(grid, start, searches=searches), route_likelihood(grid, [east], searches=searches)
    found = dict(searches.found)
    assert sorted(kind for kind, _ in found) == ["doors", "plain", "route"]  # one search from the reader
    assert np.array_equal(depth, door_depth_weight(grid, start, searches=searches))
    assert np.array_equal(route, route_likelihood(grid, [east], searches=searches))
    assert all(searches.found[key] is found[key] for key in found)  # the same map: no search run again
    grid.log_odds[60:62, :] = 3.0  # a new wall across the room
    moved = door_depth_weight(grid, start, searches=searches)
    assert np.array_equal(moved, door_depth_weight(grid, start))
    plain = next(key for key in found if key[0] == "plain")
    assert searches.found[plain] is not found[plain]  # run again on the changed map
    assert searches.found.keys() >= {key for key in found if key[0] == "route"}  # kept: only depth was asked


@pytest.mark.parametrize("style", ["office", "museum"])
def test_on_a_mapped_building_every_true_arrow_favours_the_place_it_names(style):
    """The generator writes each arrow within 40 degrees of its route's first leg: with the building mapped, the
    arrow's likelihood in front of the named goal's label is high (development seed 0)."""
    from abstract_map.prepositions import ARROWS
    from sim.world.generator import generate

    world = generate(0, style=style).world
    grid = mapped_plan(world.floorplan)
    checked = 0
    for tag in world.tags.values():
        for line in tag.text.split("\n") if tag.kind == "sign" else ():
            word, _, names = line.partition(" ")
            if word.strip("$") not in ARROWS or not word.startswith("$"):
                continue
            for name in (n for n in names.split(", ") if n in world.goals):
                label = world.tags[world.goals[name]]
                arrow = Arrow((tag.x, tag.y), tag.theta, tag.theta + ARROWS[word.strip("$")], 0.0)
                front = (label.x + 1.5 * math.cos(label.theta), label.y + 1.5 * math.sin(label.theta))
                assert at(grid, route_likelihood(grid, [arrow]), *front) > 0.4, (tag.id, word, name)
                checked += 1
    assert checked >= 5


def test_a_sign_not_naming_the_goal_discounts_what_lies_beyond_it_on_the_way_from_the_start():
    """Open floor, the start at (2, 6), a sign's reader at (10, 6): routes from the start that pass within
    ``junction_m`` of the reader and end beyond it lose ``named_prob``; routes that miss it, or end before it,
    keep all of theirs."""
    grid = grid_of([])
    params = RouteParams()
    likelihood = passed_likelihood(grid, [(10.0, 6.0)], np.array([2.0, 6.0]), params)
    assert likelihood is not None and float(likelihood.max()) == pytest.approx(1.0)
    assert at(grid, likelihood, 16.0, 6.0) == pytest.approx(1.0 - params.named_prob)  # beyond it
    assert at(grid, likelihood, 9.0, 11.5) == pytest.approx(1.0)  # the route passes about 4 m off
    assert at(grid, likelihood, 5.0, 6.0) == pytest.approx(1.0)  # before it
    assert passed_likelihood(grid, [], np.array([2.0, 6.0])) is None
    beside_the_start = passed_likelihood(grid, [(3.0, 6.0)], np.array([2.0, 6.0]), params)
    assert float(beside_the_start.min()) == pytest.approx(1.0)  # every route passes it: it says nothing


def test_a_sign_not_naming_the_goal_says_nothing_of_a_branch_the_route_leaves_before_it():
    """A wall along y = 4 from x = 0 to 12, open at its east end: places north of the wall are reached round its
    end at x 12..20, past a reader at (13, 3); the places south of it (x < 12) are reached directly."""
    grid = grid_of([(0.0, 12.0, 4.0, 4.2)])
    likelihood = passed_likelihood(grid, [(13.0, 3.0)], np.array([2.0, 2.0]))
    assert at(grid, likelihood, 4.0, 8.0) == pytest.approx(1.0 - RouteParams().named_prob)  # round the wall's end
    assert at(grid, likelihood, 8.0, 1.0) == pytest.approx(1.0)


def test_routes_keep_to_the_mapped_corridors_when_unseen_space_costs_more():
    """Two mapped corridors, east along y 0 .. 2 and north along x 10 .. 12; everything else unseen. A sign not
    naming the goal has its reader at (11, 5) in the northern one. From the start (1, 1), the shortest route to a
    place at (11, 9) over unseen space as cheap as mapped floor cuts across the unseen block, clear of the
    reader: the sign says nothing of the place. With unseen space dear enough (``unseen_cost``) the route keeps to
    the corridors, past the reader, and the place beyond the sign is discounted."""
    grid = grid_of([], (14.0, 14.0))
    xy = grid.cell_to_world(np.argwhere(np.ones(grid.shape, dtype=bool)))
    cells = grid.world_to_cell(xy)
    corridors = (xy[:, 1] < 2.0) | ((xy[:, 0] >= 10.0) & (xy[:, 0] < 12.0))
    grid.log_odds[cells[~corridors, 0], cells[~corridors, 1]] = 0.0
    reader, start, place = [(11.0, 5.0)], np.array([1.0, 1.0]), (11.0, 9.0)
    dear = RouteParams(unseen_cost=2.0)
    assert at(grid, passed_likelihood(grid, reader, start, dear), *place) == pytest.approx(1.0 - dear.named_prob)
    cheap = RouteParams(unseen_cost=1.0)
    assert at(grid, passed_likelihood(grid, reader, start, cheap), *place) == pytest.approx(1.0)


def test_path_sums_add_up_each_index_and_its_ancestors():
    pred = np.array([0, 0, 1, 2, 3, 5])  # a chain 4 -> 3 -> 2 -> 1 -> 0 (the root), and 5 on its own
    sums = path_sums(pred, np.array([7.0, 1.0, 2.0, 3.0, 4.0, 9.0]))
    assert sums.tolist() == [0.0, 1.0, 3.0, 6.0, 10.0, 0.0]  # roots count 0


def test_an_arrow_against_a_route_across_unseen_space_does_not_rule_its_place_out():
    """A corridor (y 0 .. 2) whose north wall has one gap, at x 2 .. 4, west of the reader. The robot has mapped
    the corridor and its wall up to x 10; beyond, and north of the wall, nothing. Over that map the shortest route
    to a place far to the north-east sets off east and crosses the unseen wall, against the arrow west (which is
    right: the true route takes the gap). A route that sets off west is only a little longer across the same
    unseen space, so the place stays likely; by the first leg alone it would not. The detour is priced as routes
    are (``unseen_cost`` a metre across unseen space), so the allowance is less than with unseen space as cheap
    as mapped floor, but the place stays well above the wrong arrow's 0.1."""
    size = (20.0, 30.0)
    west = Arrow(sign_xy=(8.0, 0.0), facing=math.pi / 2, direction=math.pi, wrong_prob=0.1)
    grid = grid_of([(0.0, 2.0, 2.0, 2.2), (4.0, 20.0, 2.0, 2.2)], size)
    xy = grid.cell_to_world(np.argwhere(np.ones(grid.shape, dtype=bool)))
    cells = grid.world_to_cell(xy)
    unseen = (xy[:, 1] >= 2.2) | ((xy[:, 1] >= 2.0) & (xy[:, 0] >= 10.0))
    grid.log_odds[cells[unseen, 0], cells[unseen, 1]] = 0.0
    place = (14.0, 25.0)
    assert at(grid, route_likelihood(grid, [west], RouteParams(unseen_detour=0.0)), *place) < 0.15
    assert at(grid, route_likelihood(grid, [west], RouteParams(unseen_cost=1.0)), *place) > 0.4
    assert at(grid, route_likelihood(grid, [west]), *place) > 0.25  # priced: the detour weighs unseen_cost more
    along_the_mapped_corridor = (16.0, 1.0)  # east of the reader over mapped floor: the arrow still rules it out
    assert at(grid, route_likelihood(grid, [west]), *along_the_mapped_corridor) < 0.15


def test_a_wall_takes_the_likeliest_space_in_front_of_it():
    """No route enters a wall, but a label on it is read from the space in front: a corridor's north wall
    behind the sign's reader (west, against an arrow east) is as unlikely as the corridor there, and the wall
    ahead as likely (the wall is the building's edge: nothing lies beyond it)."""
    grid = grid_of([(0.0, 20.0, 3.0, 3.2)], size=(20.0, 3.2))
    east = Arrow(sign_xy=(10.0, 1.0), facing=math.pi / 2, direction=0.0, wrong_prob=0.1)
    likelihood = route_likelihood(grid, [east])
    assert at(grid, likelihood, 3.0, 3.1) == pytest.approx(at(grid, likelihood, 3.0, 2.5), abs=0.02)
    assert at(grid, likelihood, 3.0, 3.1) < 0.15
    assert at(grid, likelihood, 17.0, 3.1) == pytest.approx(1.0, abs=0.05)


def test_walls_far_from_open_space_keep_their_own_likelihood():
    likelihood = np.array([[0.2, 0.9, 0.5, 0.5, 0.5]])
    blocked = np.array([[False, True, True, True, True]])
    out = walls_take_front(likelihood, blocked, 1.0)
    assert out.tolist() == [[0.2, 0.2, 0.5, 0.5, 0.5]]
