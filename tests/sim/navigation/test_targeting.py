"""Stand-in targets for goals imagined behind walls."""

from __future__ import annotations

import numpy as np

from sim.mapping.occupancy import OccupancyGrid, OccupancyParams
from sim.navigation.planner import PlannerParams
from sim.navigation.targeting import TargetParams, choose_target, nearest_seen_point


def seen_room() -> OccupancyGrid:
    """10 m x 8 m: seen free for x < 6 m, a seen wall at x = 6 m, unseen beyond."""
    grid = OccupancyGrid(OccupancyParams(resolution_m=0.1, bounds=(0.0, 10.0, 0.0, 8.0)))
    xy = grid.cell_to_world(np.argwhere(np.ones(grid.shape, dtype=bool)))
    cells = grid.world_to_cell(xy)
    free = xy[:, 0] < 5.95
    wall = (xy[:, 0] >= 5.95) & (xy[:, 0] < 6.15)
    grid.log_odds[cells[free, 0], cells[free, 1]] = -2.0
    grid.log_odds[cells[wall, 0], cells[wall, 1]] = 3.0
    return grid


def test_nearest_seen_point_stands_back_from_the_wall():
    point = nearest_seen_point(seen_room(), np.array([1.0, 4.0]), np.array([8.0, 4.0]), robot_radius_m=0.38,
                               view_clearance_m=1.2, view_slack_m=2.0)
    assert point is not None
    assert 6.0 - 1.25 <= point[0] <= 6.0 - 1.15  # as near the goal as 1.2 m of room allows
    assert abs(point[1] - 4.0) < 0.2


def test_a_goal_behind_a_wall_gets_a_stand_in_and_an_open_one_does_not():
    grid, robot = seen_room(), np.array([1.0, 4.0])
    # the unseen side is reachable only around the wall's ends: far longer than the straight line
    grid.log_odds[:, :] = np.where(grid.log_odds == 0.0, 3.0, grid.log_odds)  # close the unseen side
    behind = choose_target(grid, robot, np.array([8.0, 4.0]), PlannerParams(), TargetParams(), allow_detours=False)
    assert behind.local and behind.xy[0] < 6.0
    ahead = choose_target(grid, robot, np.array([4.0, 4.0]), PlannerParams(), TargetParams(), allow_detours=False)
    assert not ahead.local and np.allclose(ahead.xy, [4.0, 4.0])
    assert not choose_target(grid, robot, np.array([8.0, 4.0]), PlannerParams(), TargetParams(),
                             allow_detours=True).local
