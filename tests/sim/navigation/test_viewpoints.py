"""Readable viewpoints: where to stand to read a label the belief puts somewhere."""

from __future__ import annotations

import math

import numpy as np

from sim.mapping.occupancy import OccupancyGrid, OccupancyParams
from sim.navigation.belief import BeliefParams
from sim.navigation.planner import PlannerParams
from sim.navigation.viewpoints import ViewpointParams, score_viewpoints, travel_costs
from sim.world.visibility import readable


def room_with_wall() -> OccupancyGrid:
    """10 m x 8 m, all mapped free but a wall at x = 6.0 .. 6.2 m from y = 0 to 5 m."""
    grid = OccupancyGrid(OccupancyParams(resolution_m=0.1, bounds=(0.0, 10.0, 0.0, 8.0)))
    grid.log_odds[:, :] = -2.0
    xy = grid.cell_to_world(np.argwhere(np.ones(grid.shape, dtype=bool)))
    cells = grid.world_to_cell(xy)
    wall = (xy[:, 0] >= 6.0) & (xy[:, 0] < 6.2) & (xy[:, 1] < 5.0)
    grid.log_odds[cells[wall, 0], cells[wall, 1]] = 3.0
    return grid


def test_the_best_viewpoints_read_the_label_where_the_belief_is():
    grid = room_with_wall()
    label = (6.0, 2.5, math.pi)  # on the wall's west face, facing -x
    mass = np.zeros(grid.shape)
    rc = grid.world_to_cell(np.array(label[:2]))[0]
    mass[rc[0], rc[1]] = 1.0
    belief = BeliefParams()
    travel = travel_costs(grid, np.array([1.0, 1.0]), PlannerParams(), 20.0)
    views = score_viewpoints(grid, travel, mass, ViewpointParams(), belief)
    worth = views.value > 0
    assert worth.any()
    ok = readable(views.xy[worth, 0], views.xy[worth, 1], *label, max_range_m=belief.read_range_m,
                  cone_half_angle_deg=belief.cone_half_angle_deg + 5.0)
    assert ok.all()  # every valued viewpoint reads the label (a block's width of slack on the cone)
    assert np.all(views.xy[worth, 0] < 6.0)  # none from behind the wall
    best = views.xy[views.best()]
    assert readable(best[0], best[1], *label, max_range_m=4.0, cone_half_angle_deg=45.0)


def test_a_visited_viewpoint_is_not_chosen_again():
    grid = room_with_wall()
    mass = np.zeros(grid.shape)
    rc = grid.world_to_cell(np.array([6.0, 2.5]))[0]
    mass[rc[0], rc[1]] = 1.0
    travel = travel_costs(grid, np.array([1.0, 1.0]), PlannerParams(), 20.0, pool=2)
    first = score_viewpoints(grid, travel, mass, ViewpointParams(), BeliefParams())
    best = first.xy[first.best()]
    again = score_viewpoints(grid, travel, mass, ViewpointParams(), BeliefParams(), [best])
    assert np.hypot(*(again.xy[again.best()] - best)) >= ViewpointParams().visited_radius_m
