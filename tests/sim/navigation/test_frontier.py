"""Frontier exploration: the nearest frontier by path length, and the no-signs policy in a closed loop."""

from __future__ import annotations

import json
import shutil

import numpy as np
from skimage.graph import MCP_Geometric

from sim.mapping.occupancy import OccupancyGrid, OccupancyParams
from sim.navigation.frontier import (
    FrontierParams,
    _frontier_mask,
    find_frontiers,
    frontier_mask,
    known_box,
    nearest_frontier,
)
from sim.navigation.targeting import clearance_m, filled_free, seen_passable

PARAMS = FrontierParams()


def room_grid() -> OccupancyGrid:
    """10 m x 6 m: seen free x < 6 except a wall at x = 3 from y = 0 to 5 m; the rest unseen."""
    grid = OccupancyGrid(OccupancyParams(resolution_m=0.1, bounds=(0.0, 10.0, 0.0, 6.0)))
    xy = grid.cell_to_world(np.argwhere(np.ones(grid.shape, dtype=bool)))
    cells = grid.world_to_cell(xy)
    seen = xy[:, 0] < 6.0
    wall = (np.abs(xy[:, 0] - 3.0) < 0.15) & (xy[:, 1] < 5.0)
    grid.log_odds[cells[seen, 0], cells[seen, 1]] = -2.0
    grid.log_odds[cells[wall, 0], cells[wall, 1]] = 3.0
    return grid


def test_nearest_frontier_is_nearest_by_path_not_by_line():
    grid = room_grid()
    target = nearest_frontier(grid, np.array([2.0, 1.0]), 0.38, PARAMS)
    assert target is not None and abs(target[0] - 6.0) < 0.5  # on the boundary of seen space
    # straight-line nearest would be at y ~ 1, behind the wall; by path it is past the wall's end (y > 5)
    assert target[1] > 4.5


def test_visited_frontiers_are_skipped_and_a_known_world_has_none():
    grid = room_grid()
    first = nearest_frontier(grid, np.array([2.0, 1.0]), 0.38, PARAMS)
    second = nearest_frontier(grid, np.array([2.0, 1.0]), 0.38, PARAMS, visited=[first])
    assert second is not None and np.hypot(*(second - first)) > PARAMS.visited_radius_m
    grid.log_odds[grid.log_odds == 0.0] = -2.0  # everything seen
    assert nearest_frontier(grid, np.array([2.0, 1.0]), 0.38, PARAMS) is None


def test_frontier_policy_finds_the_label_it_cannot_see_from_the_start(tiny_world, tmp_path):
    from dataclasses import replace

    from sim.experiments.study import study_params
    from sim.experiments.trial import run_trial

    world = tmp_path / "tiny"
    shutil.copytree(tiny_world.root, world)
    meta = json.loads((world / "world.json").read_text())
    meta["start"] = {"x_m": 1.0, "y_m": 6.8, "heading_deg": 90.0}  # 5.9 m from A, facing away from it
    (world / "world.json").write_text(json.dumps(meta))
    params = replace(study_params("geometric"), max_sim_s=240.0)
    result = run_trial(str(world), "A", seed=0, perception="geometric", navigator="frontier", params=params)
    assert result.success, result.reason
    assert result.distance_m > 0.5 and result.cues == [] and result.navigator == "frontier"


def test_a_look_is_taken_again_only_after_the_robot_moves_or_the_map_grows():
    from sim.navigation.frontier import LookedAt

    grid = OccupancyGrid(OccupancyParams(resolution_m=0.1, bounds=(0.0, 10.0, 0.0, 10.0)))
    grid.log_odds[:] = -2.0  # all mapped free
    params = FrontierParams()
    looked = LookedAt()
    covered = looked.update(grid, np.array([2.0, 5.0]), params)
    assert covered.any() and looked.at is not None
    covered[:] = False  # a look now would mark cells again
    assert not looked.update(grid, np.array([2.05, 5.0]), params).any()  # moved 5 cm: no look
    assert looked.update(grid, np.array([2.5, 5.0]), params).any()  # moved 0.5 m: looks
    covered[:] = False
    grid.version += 1  # the map grew
    assert looked.update(grid, np.array([2.5, 5.0]), params).any()


def speckled_grid(seed: int) -> OccupancyGrid:
    """20 m x 12 m, mostly unseen: a seen patch in the middle with walls, a doorway and unseen specks."""
    rng = np.random.default_rng(seed)
    grid = OccupancyGrid(OccupancyParams(resolution_m=0.1, bounds=(0.0, 20.0, 0.0, 12.0)))
    grid.log_odds[30:90, 40:150] = -2.0
    grid.log_odds[30:90, 95:97] = 3.0  # a wall across the patch ...
    grid.log_odds[55:65, 95:97] = -2.0  # ... with a doorway
    grid.log_odds[30:32, 40:150] = 3.0
    specks = rng.random(grid.shape) < 0.03
    grid.log_odds[specks & (grid.log_odds < 0)] = 0.0
    return grid


def test_frontier_mask_on_the_known_box_is_the_whole_grids():
    for seed in range(3):
        grid = speckled_grid(seed)
        covered = np.zeros(grid.shape, dtype=bool)
        covered[30:90, 40:100] = True
        for looked in (None, covered):
            frontier, passable = frontier_mask(grid, 0.38, PARAMS, looked)
            whole_frontier, whole_passable = _frontier_mask(grid, 0.38, PARAMS, looked)
            assert frontier.any() and np.array_equal(frontier, whole_frontier)
            assert np.array_equal(passable, whole_passable)
            # the capped clearance judges passability as the exact distance transform does
            exact = seen_passable(grid, clearance_m(grid), 0.38, PARAMS.fill_holes_cells,
                                  filled_free(grid, PARAMS.fill_holes_cells))
            assert np.array_equal(passable, exact)
    box = known_box(grid, 5)
    assert box == (slice(25, 95), slice(35, 155))
    assert known_box(OccupancyGrid(OccupancyParams(bounds=(0.0, 2.0, 0.0, 2.0))), 5) is None


def test_frontier_path_lengths_are_the_whole_grids():
    grid = speckled_grid(0)
    robot = np.array([6.0, 6.0])
    found = find_frontiers(grid, robot, 0.38, PARAMS)
    _, passable = frontier_mask(grid, 0.38, PARAMS)
    start = tuple(grid.world_to_cell(robot)[0])
    assert passable[start]
    whole, _ = MCP_Geometric(np.where(passable, 1.0, np.inf), fully_connected=True).find_costs([start])
    finite = np.isfinite(whole)
    assert finite.sum() > 1000 and np.array_equal(np.isfinite(found.distance_m), finite)
    assert np.max(np.abs(found.distance_m[finite] - whole[finite] * grid.resolution)) < 1e-9


def test_a_look_stops_at_walls_and_kept_rays_mark_the_same_cells():
    from sim.navigation.frontier import look, look_rays

    grid = room_grid()  # a wall at x = 3 m from y = 0 to 5 m
    robot = np.array([2.0, 2.0])
    fresh, kept = np.zeros(grid.shape, dtype=bool), np.zeros(grid.shape, dtype=bool)
    look(grid, fresh, robot, PARAMS)
    look(grid, kept, robot, PARAMS, look_rays(grid, PARAMS))
    assert np.array_equal(fresh, kept)
    seen = lambda x, y: bool(fresh[tuple(grid.world_to_cell(np.array([x, y]))[0])])  # noqa: E731
    assert seen(1.0, 2.0) and seen(2.85, 2.0)  # free, and the wall's first cell
    assert not seen(3.05, 2.0) and not seen(3.5, 2.0)  # in and behind the wall
    assert not seen(1.0, 5.4)  # free and in line of sight, but 3.5 m away: beyond look_radius_m
