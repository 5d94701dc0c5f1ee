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


def door_grid() -> OccupancyGrid:
    """10 m x 6 m, all mapped: a corridor below a wall at y = 2.0-2.2 m with a 1 m doorway at x = 4-5 m."""
    grid = OccupancyGrid(OccupancyParams(resolution_m=0.1, bounds=(0.0, 10.0, 0.0, 6.0)))
    xy = grid.cell_to_world(np.argwhere(np.ones(grid.shape, dtype=bool)))
    cells = grid.world_to_cell(xy)
    grid.log_odds[cells[:, 0], cells[:, 1]] = -2.0
    wall = (xy[:, 1] > 2.0) & (xy[:, 1] < 2.2) & ~((xy[:, 0] > 4.0) & (xy[:, 0] < 5.0))
    grid.log_odds[cells[wall, 0], cells[wall, 1]] = 3.0
    return grid


def test_label_walls_are_the_faces_beside_a_doorway_on_both_sides():
    from sim.navigation.frontier import label_walls, wall_faces

    grid = door_grid()
    walls = label_walls(grid.occupied_mask(), grid.free_mask(), grid.resolution, PARAMS)
    xy = grid.cell_to_world(np.argwhere(walls))
    assert walls.sum() == 32  # 8 cells (0.8 m) each side of the doorway, on both faces of the 2-cell wall
    assert xy[:, 0].min() > 3.2 and xy[:, 0].max() < 5.8 and not ((xy[:, 0] > 4.0) & (xy[:, 0] < 5.0)).any()
    every = wall_faces(grid.occupied_mask(), grid.free_mask(), grid.resolution, PARAMS)
    assert every.sum() == grid.occupied_mask().sum() and (walls <= every).all()
    grid.log_odds[grid.log_odds > 0] = -2.0  # no wall: no doorway, no label wall
    assert not label_walls(grid.occupied_mask(), grid.free_mask(), grid.resolution, PARAMS).any()


def test_a_gap_across_unseen_space_or_as_wide_as_a_corridor_is_no_doorway():
    from sim.navigation.frontier import label_walls

    grid = door_grid()
    rows = grid.world_to_cell(np.array([[4.5, 2.05], [4.5, 2.15]]))[:, 0]
    grid.log_odds[rows, 44:46] = 0.0  # the doorway's middle unseen: its width is not known
    assert not label_walls(grid.occupied_mask(), grid.free_mask(), grid.resolution, PARAMS).any()
    wide = door_grid()
    wide.log_odds[rows, 35:60] = -2.0  # a 2.5 m gap: the end of a corridor, not a door
    assert not label_walls(wide.occupied_mask(), wide.free_mask(), wide.resolution, PARAMS).any()


def test_a_look_reads_a_wall_only_within_the_reading_cone():
    from sim.navigation.frontier import look, wall_normals

    grid = door_grid()
    occupied = grid.occupied_mask()
    rows, cols = np.nonzero(occupied)
    normals = wall_normals(occupied, rows, cols)
    y = grid.cell_to_world(np.stack([rows, cols], axis=1))[:, 1]
    assert np.allclose(normals[y < 2.1], [0.0, -1.0]) or (np.abs(normals[y < 2.1][:, 1] + 1) < 0.3).all()
    assert (normals[y > 2.1][:, 1] > 0.7).all()  # the upper face looks up, into the room
    covered = np.zeros(grid.shape, dtype=bool)
    look(grid, covered, np.array([2.0, 1.0]), PARAMS)  # 1.05 m below the wall's face
    read = grid.cell_to_world(np.argwhere(covered & occupied))
    half = 1.05 * np.tan(np.radians(PARAMS.look_cone_deg))
    assert np.all(np.abs(read[:, 0] - 2.0) <= half + 0.1) and np.all(read[:, 1] < 2.1)
    assert read[:, 0].min() < 2.0 - half + 0.3 and read[:, 0].max() > 2.0 + half - 0.3
    assert covered[tuple(grid.world_to_cell(np.array([2.0, 0.5]))[0])]  # open floor in sight is marked too


def test_unread_label_walls_draw_the_search_until_looked_at():
    from dataclasses import replace

    from sim.navigation.frontier import look

    grid = door_grid()  # everything mapped: only walls not yet looked at can be frontiers
    covered = np.zeros(grid.shape, dtype=bool)
    assert nearest_frontier(grid, np.array([8.0, 1.0]), 0.38, PARAMS) is None  # no mask: nothing unseen
    target = nearest_frontier(grid, np.array([8.0, 1.0]), 0.38, PARAMS, covered=covered)
    assert target is not None and 2.4 < target[0] < 6.6  # within face_reach_m of the walls by the doorway
    for x in (3.5, 4.5, 5.5):  # walk past the doorway on both sides, 1 m from the wall
        look(grid, covered, np.array([x, 1.0]), PARAMS)
        look(grid, covered, np.array([x, 3.2]), PARAMS)
    assert nearest_frontier(grid, np.array([8.0, 1.0]), 0.38, PARAMS, covered=covered) is None
    every = replace(PARAMS, walls="all")  # the second pass: the rest of the wall, not yet looked at
    assert nearest_frontier(grid, np.array([8.0, 1.0]), 0.38, every, covered=covered) is not None


def test_a_wall_not_yet_looked_at_draws_the_search_to_its_own_side_only():
    from sim.navigation.frontier import look

    grid = door_grid()
    covered = np.zeros(grid.shape, dtype=bool)
    for x in (3.5, 4.5, 5.5):  # the corridor side looked at; the room side (y > 2.2 m) not
        look(grid, covered, np.array([x, 1.0]), PARAMS)
    frontier, _ = frontier_mask(grid, 0.38, PARAMS, covered)
    ys = grid.cell_to_world(np.argwhere(frontier))[:, 1]
    assert ys.size and (ys > 2.2).all()  # in the room, in front of the faces still to read


def test_only_the_approach_side_of_a_doorway_must_be_looked_at():
    from sim.navigation.frontier import label_walls

    grid = door_grid()  # corridor below y = 2 m (no doorway from the start), room above (through one)
    doors = np.where(grid.cell_to_world(np.argwhere(np.ones(grid.shape, dtype=bool)))[:, 1] > 2.1, 1.0, 0.0)
    doors = doors.reshape(grid.shape)
    walls = label_walls(grid.occupied_mask(), grid.free_mask(), grid.resolution, PARAMS, doors)
    ys = grid.cell_to_world(np.argwhere(walls))[:, 1]
    assert walls.sum() == 16 and np.allclose(ys, 2.05)  # the corridor's face only: the room's carries no label
    walls = label_walls(grid.occupied_mask(), grid.free_mask(), grid.resolution, PARAMS, 1.0 - doors)
    assert np.allclose(grid.cell_to_world(np.argwhere(walls))[:, 1], 2.15)  # approached from the room instead


def test_door_counts_count_the_doorways_from_the_start():
    from sim.navigation.routes import door_counts

    grid = door_grid()
    doors = door_counts(grid, np.array([2.0, 1.0]))
    at = lambda x, y: float(doors[tuple(grid.world_to_cell(np.array([x, y]))[0])])  # noqa: E731
    assert at(8.0, 1.0) < 0.2 and 0.7 < at(4.5, 4.0) < 1.5  # the corridor, and the room through the doorway
