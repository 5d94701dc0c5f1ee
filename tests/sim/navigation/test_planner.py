"""Planning over synthetic occupancy grids: unseen space, walls, blocked goals, re-planning."""

import math

import numpy as np
import pytest
from scipy import ndimage

from sim.mapping.occupancy import OccupancyGrid, OccupancyParams
from sim.navigation.planner import PlannerParams, cost_map, distance_to_occupied, plan
from sim.navigation.replanner import Replanner, ReplanParams, path_blocked

RES = 0.1
BOUNDS = (0.0, 20.0, 0.0, 10.0)
PARAMS = PlannerParams()


def unknown_grid() -> OccupancyGrid:
    return OccupancyGrid(OccupancyParams(resolution_m=RES, bounds=BOUNDS))


def set_cells(grid: OccupancyGrid, x0: float, x1: float, y0: float, y1: float, occupied: bool) -> None:
    """Mark the cells whose centres lie in [x0, x1] x [y0, y1] (m) occupied or free."""
    centres = grid.cell_to_world(np.argwhere(np.ones(grid.shape, dtype=bool))).reshape(*grid.shape, 2)
    inside = ((centres[..., 0] >= x0) & (centres[..., 0] <= x1)
              & (centres[..., 1] >= y0) & (centres[..., 1] <= y1))
    grid.log_odds[inside] = grid.params.clamp[1] if occupied else grid.params.clamp[0]
    grid.version += 1  # the map changed (as OccupancyGrid.integrate counts it)


def dense(waypoints: np.ndarray, step: float = 0.01) -> np.ndarray:
    """Points every ``step`` m along a polyline."""
    parts = [a + np.linspace(0, 1, max(2, int(np.hypot(*(b - a)) / step)))[:, None] * (b - a)
             for a, b in zip(waypoints[:-1], waypoints[1:])]
    return np.concatenate(parts)


def clearance_to_boxes(points: np.ndarray, grid: OccupancyGrid) -> float:
    """Smallest distance (m) from ``points`` to the squares of occupied cells."""
    centres = grid.cell_to_world(np.argwhere(grid.occupied_mask()))
    half = grid.resolution / 2
    gap = np.maximum(np.abs(points[:, None, :] - centres[None, :, :]) - half, 0.0)
    return float(np.min(np.hypot(gap[..., 0], gap[..., 1])))


def test_unknown_space_is_crossed_in_a_straight_line() -> None:
    grid = unknown_grid()
    start, goal = np.array([1.0, 1.3]), np.array([18.7, 8.1])
    result = plan(grid, start, goal, PARAMS)
    assert result is not None and result.goal_reached_exactly
    straight = float(np.hypot(*(goal - start)))
    assert result.length_m <= 1.05 * straight
    assert result.waypoints[0] == pytest.approx(start) and result.waypoints[-1] == pytest.approx(goal)


def test_straight_line_also_after_a_search() -> None:
    grid = unknown_grid()
    set_cells(grid, 9.0, 9.2, 0.0, 2.0, occupied=True)  # a stub near the line forces the full search
    start, goal = np.array([1.0, 2.5]), np.array([19.0, 6.5])
    result = plan(grid, start, goal, PARAMS)
    assert result is not None
    assert result.length_m <= 1.05 * float(np.hypot(*(goal - start)))
    assert len(result.waypoints) <= 6


@pytest.mark.parametrize("params", [PARAMS, PlannerParams(inflation_cost=0.0)], ids=["soft band", "hard only"])
def test_path_goes_around_a_known_wall_with_clearance(params: PlannerParams) -> None:
    grid = unknown_grid()
    set_cells(grid, 9.9, 10.1, 0.0, 7.0, occupied=True)  # wall from the bottom edge up to y = 7
    start, goal = np.array([5.0, 2.0]), np.array([15.0, 2.0])
    result = plan(grid, start, goal, params)
    assert result is not None and result.goal_reached_exactly
    points = dense(result.waypoints)
    lethal = cost_map(grid, params).lethal
    cells = grid.world_to_cell(points)
    assert not lethal[cells[:, 0], cells[:, 1]].any()  # no segment crosses the inflated wall
    crossing = points[np.abs(points[:, 0] - 10.0) < 0.05]
    assert crossing[:, 1].min() > 7.0 + params.robot_radius_m - RES / 2  # it went over the wall's end
    # Cells are passable when their centre clears the wall by the radius; the path may be half a cell off-centre.
    assert clearance_to_boxes(points, grid) >= params.robot_radius_m - RES / math.sqrt(2)
    assert result.length_m < 1.1 * (2 * math.hypot(5.0, 5.0 + params.robot_radius_m))


def test_soft_cost_keeps_to_the_middle_of_a_corridor() -> None:
    grid = unknown_grid()
    set_cells(grid, 0.0, 20.0, 0.0, 4.0, occupied=True)
    set_cells(grid, 0.0, 20.0, 6.0, 10.0, occupied=True)
    set_cells(grid, 0.0, 20.0, 4.05, 5.95, occupied=False)  # a 2 m corridor, y 4..6
    result = plan(grid, (1.0, 4.6), (19.0, 5.4), PARAMS)
    assert result is not None
    middle = dense(result.waypoints)
    middle = middle[(middle[:, 0] > 5) & (middle[:, 0] < 15)]
    assert np.all(np.abs(middle[:, 1] - 5.0) < 0.35)


def test_goal_inside_a_wall_plans_to_a_nearby_reachable_cell() -> None:
    grid = unknown_grid()
    set_cells(grid, 9.5, 10.5, 3.0, 7.0, occupied=True)  # a 1 m thick block
    goal = np.array([10.0, 5.0])
    result = plan(grid, (3.0, 5.0), goal, PARAMS)
    assert result is not None and not result.goal_reached_exactly
    end = np.array(result.goal_xy)
    assert result.waypoints[-1] == pytest.approx(end)
    assert np.hypot(*(end - goal)) < 0.5 + PARAMS.robot_radius_m + 2 * RES
    assert end[0] < 10.0  # the side the robot comes from
    assert not cost_map(grid, PARAMS).lethal[tuple(grid.world_to_cell(end)[0])]


def test_goal_off_the_grid_plans_to_the_edge() -> None:
    result = plan(unknown_grid(), (3.0, 5.0), (25.0, 5.0), PARAMS)
    assert result is not None and not result.goal_reached_exactly
    assert result.goal_xy[0] == pytest.approx(19.95) and result.goal_xy[1] == pytest.approx(5.05, abs=0.06)


def test_enclosed_start_has_no_path() -> None:
    grid = unknown_grid()
    set_cells(grid, 2.0, 6.0, 2.0, 6.0, occupied=True)
    set_cells(grid, 2.15, 5.85, 2.15, 5.85, occupied=False)  # a closed 4 m box, walls ~0.2 m thick
    assert plan(grid, (4.0, 4.0), (15.0, 5.0), PARAMS) is None
    inside = plan(grid, (3.0, 3.0), (5.0, 5.0), PARAMS)
    assert inside is not None and inside.goal_reached_exactly


def test_start_brushing_a_wall_can_escape() -> None:
    grid = unknown_grid()
    set_cells(grid, 0.0, 20.0, 4.9, 5.1, occupied=True)
    start = np.array([8.0, 5.35])  # 0.25 m from the wall face: inside the impassable band
    assert cost_map(grid, PARAMS).lethal[tuple(grid.world_to_cell(start)[0])]
    result = plan(grid, start, (12.0, 8.0), PARAMS)
    assert result is not None and result.goal_reached_exactly
    assert result.waypoints[0] == pytest.approx(start)


def test_dear_unknown_space_prefers_a_known_corridor() -> None:
    grid = unknown_grid()
    set_cells(grid, 1.0, 19.0, 7.0, 9.0, occupied=False)  # known free lane along y = 8
    params = PlannerParams(unknown_cost=3.0)
    start, goal = (1.5, 2.0), (18.5, 2.0)
    cheap = plan(grid, start, goal, PARAMS)
    dear = plan(grid, start, goal, params)
    assert cheap is not None and dear is not None
    assert cheap.length_m == pytest.approx(17.0, abs=0.1)
    assert dense(dear.waypoints)[:, 1].max() > 7.0


def test_coarse_search_matches_a_single_fine_search() -> None:
    grid = unknown_grid()
    for x in (4.0, 8.0, 12.0, 16.0):
        low = x in (4.0, 12.0)
        set_cells(grid, x - 0.1, x + 0.1, 0.0 if low else 3.0, 7.0 if low else 10.0, occupied=True)
    coarse = plan(grid, (1.0, 5.0), (19.0, 5.0), PARAMS)
    fine = plan(grid, (1.0, 5.0), (19.0, 5.0), PlannerParams(coarse_factor=1))
    assert coarse is not None and fine is not None
    assert coarse.length_m == pytest.approx(fine.length_m, rel=0.05)


def test_capped_distance_matches_the_exact_transform() -> None:
    occupied = np.random.default_rng(3).random((80, 120)) < 0.02
    capped = distance_to_occupied(occupied, 6)
    exact = ndimage.distance_transform_edt(~occupied)
    near = exact <= 6
    assert np.allclose(capped[near], exact[near])
    assert np.all(capped[~near] > 6)


def test_new_wall_blocks_the_path_and_triggers_a_replan() -> None:
    grid = unknown_grid()
    replanner = Replanner(ReplanParams(period_s=100.0, min_interval_s=0.5), PARAMS)
    first = replanner.update(0.0, grid, (2.0, 5.0), (18.0, 5.0))
    assert first is not None and replanner.last_reason == "no plan yet"
    assert not path_blocked(grid, first.waypoints, PARAMS, robot_xy=(2.0, 5.0))
    assert replanner.update(1.0, grid, (3.0, 5.0), (18.0, 5.0)) is first

    set_cells(grid, 9.9, 10.1, 2.0, 8.0, occupied=True)
    assert path_blocked(grid, first.waypoints, PARAMS, robot_xy=(3.0, 5.0))
    assert not path_blocked(grid, first.waypoints, PARAMS, robot_xy=(12.0, 5.0))  # the wall is behind
    second = replanner.update(2.0, grid, (3.0, 5.0), (18.0, 5.0))
    assert replanner.last_reason == "path blocked" and second is not first
    assert second is not None and not path_blocked(grid, second.waypoints, PARAMS, robot_xy=(3.0, 5.0))


def test_replanner_triggers_on_goal_moves_period_and_requests() -> None:
    grid = unknown_grid()
    replanner = Replanner(ReplanParams(goal_moved_m=1.0, period_s=5.0, min_interval_s=0.5), PARAMS)
    replanner.update(0.0, grid, (2.0, 5.0), (18.0, 5.0))
    assert replanner.reason(0.2, grid, (2.0, 5.0), (18.0, 8.0)) is None  # too soon after the last plan
    assert replanner.reason(1.0, grid, (2.0, 5.0), (18.0, 5.5)) is None
    assert replanner.reason(1.0, grid, (2.0, 5.0), (18.0, 8.0)) == "goal moved"
    assert replanner.reason(1.0, grid, (2.0, 7.0), (18.0, 5.0)) == "off path"
    assert replanner.reason(5.0, grid, (2.0, 5.0), (18.0, 5.0)) == "periodic"
    replanner.request()
    assert replanner.reason(0.1, grid, (2.0, 5.0), (18.0, 5.0)) == "requested"


def test_bad_inputs_are_named() -> None:
    grid = unknown_grid()
    with pytest.raises(ValueError, match="goal_xy"):
        plan(grid, (1.0, 1.0), (np.nan, 1.0))
    with pytest.raises(ValueError, match="start_xy"):
        plan(grid, (-5.0, 1.0), (1.0, 1.0))
    with pytest.raises(ValueError, match="robot_radius_m"):
        PlannerParams(robot_radius_m=-1.0)
