"""Negative information: swept space and the goal belief."""

from __future__ import annotations

import numpy as np
import pytest

from sim.mapping.occupancy import OccupancyGrid, OccupancyParams
from sim.navigation.belief import (
    BeliefParams,
    GoalPrior,
    MixedPrior,
    SweptSpace,
    across_ratio,
    cue_mass,
    goal_belief,
    goal_sigma,
    labels_near_places,
    place_density,
    prior_components,
    sight_clear,
)

WALL_X = 6.0  # m, a mapped wall's west face


def corridor() -> OccupancyGrid:
    """10 m x 8 m: mapped free for x < 6 m, a mapped wall at x = 6.0 .. 6.2 m, unseen beyond."""
    grid = OccupancyGrid(OccupancyParams(resolution_m=0.1, bounds=(0.0, 10.0, 0.0, 8.0)))
    xy = grid.cell_to_world(np.argwhere(np.ones(grid.shape, dtype=bool)))
    cells = grid.world_to_cell(xy)
    free, wall = xy[:, 0] < WALL_X, (xy[:, 0] >= WALL_X) & (xy[:, 0] < WALL_X + 0.2)
    grid.log_odds[cells[free, 0], cells[free, 1]] = -2.0
    grid.log_odds[cells[wall, 0], cells[wall, 1]] = 3.0
    return grid


def wall_cells_at(grid: OccupancyGrid, y: float) -> tuple[int, int]:
    return tuple(grid.world_to_cell(np.array([WALL_X + 0.05, y]))[0])


def test_a_look_sweeps_the_wall_face_in_range_and_cone_only():
    grid = corridor()
    space = SweptSpace(grid, BeliefParams())
    space.sweep(grid, (WALL_X - 2.5, 4.0))
    assert space.swept[wall_cells_at(grid, 4.0)]  # straight ahead, 2.5 m
    assert space.swept[wall_cells_at(grid, 5.5)]  # 31 deg off the normal
    assert not space.swept[wall_cells_at(grid, 7.0)]  # 50 deg off: outside the reading cone
    assert not space.swept[tuple(grid.world_to_cell(np.array([WALL_X + 0.15, 4.0]))[0])]  # the far face
    far = SweptSpace(grid, BeliefParams())
    far.sweep(grid, (1.0, 4.0))  # 5 m away: out of range
    assert not far.swept.any()


def test_walls_block_the_sight_line():
    grid = corridor()
    occupied = grid.occupied_mask()
    clear = sight_clear(occupied, grid, np.array([2.0, 4.0]), np.array([[5.0, 4.0], [8.0, 4.0]]), 0.09)
    assert clear.tolist() == [True, False]


def test_swept_cells_lose_their_belief_and_the_rest_renormalises():
    grid, params = corridor(), BeliefParams()
    swept = np.zeros(grid.shape, dtype=bool)
    before = goal_belief(grid, swept, GoalPrior(np.array([7.0, 4.0]), 2.0), params)
    assert before.mass.sum() == pytest.approx(1.0, rel=1e-5)
    assert before.mass[grid.free_mask()].sum() == 0.0  # labels hang on walls, never in mapped free space
    space = SweptSpace(grid, params)
    space.sweep(grid, (WALL_X - 2.0, 4.0))
    after = goal_belief(grid, space.swept, GoalPrior(np.array([7.0, 4.0]), 2.0), params)
    assert after.mass.sum() == pytest.approx(1.0, rel=1e-5)
    ratio = after.mass[space.swept].sum() / before.mass[space.swept].sum()
    rest = after.mass[~space.swept].sum() / before.mass[~space.swept].sum()
    assert ratio < 0.5 < 1.0 < rest  # mass left the swept wall for the unswept cells
    assert after.remaining < before.remaining


def test_goal_spread_grows_with_distance_from_evidence():
    params = BeliefParams()
    near = goal_sigma(np.array([1.0, 0.0]), np.array([[0.0, 0.0]]), params)
    far = goal_sigma(np.array([30.0, 0.0]), np.array([[0.0, 0.0]]), params)
    assert near < far


def test_goal_spread_is_wider_the_less_surely_the_cues_name_the_goal():
    """Near evidence the spread is the floor for how the goal is named: a phrase, an arrow, the hierarchy alone;
    far from it the distance to the evidence rules whatever the naming."""
    params = BeliefParams(sigma_min_arrow_m=8.4, sigma_min_hierarchy_m=9.9)  # the measured floors (not the defaults)
    goal, anchors = np.array([1.0, 0.0]), np.array([[0.0, 0.0]])
    spreads = [goal_sigma(goal, anchors, params, placed_by=kind) for kind in ("phrase", "arrow", "hierarchy")]
    assert spreads == pytest.approx([np.hypot(f, params.label_offset_m) for f in
                                     (params.sigma_min_m, params.sigma_min_arrow_m, params.sigma_min_hierarchy_m)])
    assert spreads[0] < spreads[1] < spreads[2]
    assert goal_sigma(goal, anchors, params) == spreads[0]
    far = np.array([100.0, 0.0])
    assert goal_sigma(far, anchors, params, placed_by="phrase") == goal_sigma(far, anchors, params,
                                                                              placed_by="hierarchy")
    with pytest.raises(ValueError, match="placed_by must be one of"):
        goal_sigma(goal, anchors, params, placed_by="rumour")


def test_goal_spread_follows_the_models_own_misses():
    """The spread starts from the guess and moves to the misses' per-axis rms as labels are read."""
    params = BeliefParams()
    goal, anchors = np.array([1.0, 0.0]), np.array([[0.0, 0.0]])
    guess = goal_sigma(goal, anchors, params)
    assert goal_sigma(goal, anchors, params, []) == pytest.approx(guess)
    wide = goal_sigma(goal, anchors, params, [20.0] * 3)
    assert wide == pytest.approx(np.sqrt((3 * guess ** 2 + 3 * 200.0) / 6))
    assert goal_sigma(goal, anchors, params, [20.0] * 300) == pytest.approx(20.0 / np.sqrt(2), rel=0.02)
    assert goal_sigma(goal, anchors, params, [1.0] * 30) < guess


def test_cue_mass_is_unswept_wall_near_the_robot():
    grid, params = corridor(), BeliefParams()
    mass = cue_mass(grid, np.zeros(grid.shape, dtype=bool), np.array([3.0, 4.0]), 4.0, params)
    assert mass.sum() == pytest.approx(1.0)
    assert mass[grid.free_mask()].sum() == 0.0
    far = grid.world_to_cell(np.array([[9.5, 0.5]]))[0]
    assert mass[far[0], far[1]] == 0.0


def test_prior_without_siblings_is_the_imagined_goal():
    prior = GoalPrior(np.array([3.0, 4.0]), 5.0)
    [(weight, centre, spread)] = prior_components(prior, BeliefParams())
    assert weight == 1.0 and spread == 5.0 and centre.tolist() == [3.0, 4.0]


def test_each_estimate_counts_by_its_precision():
    """Spread 20 m against the family's 6.5 m: the siblings share 90% of the prior, each at its own label."""
    params = BeliefParams()
    sf = params.family_sigma_m
    comps = prior_components(GoalPrior(np.array([0.0, 0.0]), 20.0, np.array([[30.0, 0.0], [0.0, 40.0]])), params)
    (own, centre, spread), *family = comps
    assert own == pytest.approx(sf ** 2 / (400.0 + sf ** 2)) and own < 0.1
    assert centre.tolist() == [0.0, 0.0] and spread == 20.0
    assert [w for w, _, _ in family] == pytest.approx([(1 - own) / 2] * 2)
    assert [c.tolist() for _, c, _ in family] == [[30.0, 0.0], [0.0, 40.0]]
    assert all(s == sf for _, _, s in family)
    sharp = prior_components(GoalPrior(np.array([0.0, 0.0]), 2.0, np.array([[30.0, 0.0]])), params)
    assert sharp[0][0] > 0.9  # a model trusted to 2 m keeps its own estimate


def test_belief_moves_to_where_siblings_were_read():
    """The model imagines the goal at the wall's south end; a sibling's label read at its north end draws the
    belief north when the model is not trusted."""
    grid, params = corridor(), BeliefParams()
    swept = np.zeros(grid.shape, dtype=bool)
    alone = goal_belief(grid, swept, GoalPrior(np.array([7.0, 0.0]), 10.0), params)
    family = goal_belief(grid, swept, GoalPrior(np.array([7.0, 0.0]), 10.0, np.array([[7.0, 8.0]])), params)
    top = wall_cells_at(grid, 7.0)
    bottom = wall_cells_at(grid, 1.0)
    assert family.mass[top].sum() > alone.mass[top].sum()
    assert family.mass[bottom].sum() < alone.mass[bottom].sum()


def corridor_labels(areas: list[str]) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Three labels on a corridor's north wall (y = 2.4 m, facing south) and three on its south wall (y = 0,
    facing north), 5 m apart, of ``areas`` in that order."""
    xy = np.array([(0.0, 2.4), (5.0, 2.4), (10.0, 2.4), (1.0, 0.0), (6.0, 0.0), (11.0, 0.0)])
    facing = np.array([-np.pi / 2] * 3 + [np.pi / 2] * 3)
    return xy, facing, areas


def test_the_way_labels_face_is_learned_from_the_labels_read():
    """Areas as blocks (one area each side of the corridor): a sibling says little of the far wall. One area on
    both sides (a zoo's path): the far wall counts as the near one. Nothing read: even all round."""
    params = BeliefParams()
    blocks = across_ratio(*corridor_labels(["A"] * 3 + ["B"] * 3), params)
    assert 0.05 < blocks < 0.2
    assert across_ratio(*corridor_labels(["A"] * 6), params) == 1.0
    assert across_ratio(np.zeros((0, 2)), np.zeros(0), [], params) == 1.0
    few = across_ratio(corridor_labels(["A", "B"])[0][[0, 3]], np.array([-np.pi / 2, np.pi / 2]), ["A", "B"], params)
    assert blocks < few < 1.0  # one pair moves the pseudo-pairs' even start a little


def test_a_siblings_share_across_the_way_its_label_faces_moves_to_its_own_wall():
    """A sibling's label on the mapped wall's west face (x = 6 m, facing west), the model trusted little (30 m):
    with ``family_across`` a tenth, the space 0.5-4 m west of it (across the corridor) loses density to the
    wall's side and the far side of the wall, and the density keeps its sum."""
    grid, params = corridor(), BeliefParams()
    label = np.array([[WALL_X, 4.0]])
    even = GoalPrior(np.array([2.0, 4.0]), 30.0, label, np.array([np.pi]), 1.0)
    sided = GoalPrior(np.array([2.0, 4.0]), 30.0, label, np.array([np.pi]), 0.1)
    a, b = place_density(grid, even, params), place_density(grid, sided, params)
    assert b.sum() == pytest.approx(a.sum(), rel=1e-6)
    across = grid.world_to_cell(np.array([[WALL_X - 2.0, 4.0]]))[0]
    behind = grid.world_to_cell(np.array([[WALL_X + 1.0, 4.0]]))[0]
    assert b[tuple(across)] < 0.5 * a[tuple(across)]
    assert b[tuple(behind)] > a[tuple(behind)]


def test_facings_that_do_not_match_the_siblings_are_refused():
    grid = corridor()
    prior = GoalPrior(np.array([2.0, 4.0]), 3.0, np.array([[WALL_X, 4.0], [WALL_X, 6.0]]), np.array([np.pi]), 0.1)
    with pytest.raises(ValueError, match="one facing per sibling label"):
        place_density(grid, prior, BeliefParams())


def test_a_mixed_prior_weighs_each_part_as_a_whole_over_the_grid():
    """A part of weight 1 is the plain prior; a narrow prior at the wall's south end mixed half and half with
    one a kilometre wide puts on the north half of the wall the mean of what each alone puts there, although
    the wide one's density is a million times thinner."""
    grid, params = corridor(), BeliefParams()
    swept = np.zeros(grid.shape, dtype=bool)
    narrow, even = GoalPrior(np.array([7.0, 0.0]), 2.0), GoalPrior(np.array([7.0, 0.0]), 1000.0)
    alone = goal_belief(grid, swept, narrow, params)
    assert np.allclose(goal_belief(grid, swept, MixedPrior(((1.0, narrow), (0.0, even))), params).mass, alone.mass)
    mixed = goal_belief(grid, swept, MixedPrior(((0.5, narrow), (0.5, even))), params)
    north = grid.world_to_cell(np.array([[WALL_X, 4.0]]))[0, 0]  # rows above this lie north
    spread = goal_belief(grid, swept, even, params)
    assert alone.mass[:north].sum() < 0.25 < 0.45 < spread.mass[:north].sum()
    assert mixed.mass[:north].sum() == pytest.approx((alone.mass[:north].sum() + spread.mass[:north].sum()) / 2,
                                                     abs=0.02)
    assert mixed.centre == alone.centre and mixed.sigma_m == alone.sigma_m


def test_a_places_share_goes_to_the_wall_about_it():
    """One place in unseen space (wall chance 0.05), a mapped wall line 1 m east of it and another 12 m west:
    the place's whole share stays within reach of it, the near line taking its part by wall chance and the
    far line none."""
    wall = np.full((400, 400), 0.05)
    wall[:, 210] = 1.0  # 1 m east of the place, at 0.1 m cells
    wall[:, 80] = 1.0  # 12 m west
    density = np.zeros_like(wall)
    density[200, 200] = 1.0
    label = labels_near_places(density, wall, reach_cells=20.0)
    assert label.sum() == pytest.approx(1.0, abs=1e-3)
    assert label[:, 80].sum() < 1e-6
    near_line = label[:, 210].sum()
    assert 0.15 < near_line < 0.5  # one line of mapped wall against the unseen space about the place
    assert label[200, 210] > 10 * label[200, 190]  # a mapped cell beside the place outweighs an unseen one


def test_mapped_rooms_far_off_do_not_draw_the_belief_from_the_unseen_space_about_the_goal():
    """The imagined goal at (8, 6) m in unseen space; a mapped block of rooms (walls every metre) 10 m east.
    Weighting each cell by wall chance alone gave the block 0.12 of the belief; handed out place by place
    it keeps little more than the prior's mass near the block."""
    grid = OccupancyGrid(OccupancyParams(resolution_m=0.1, bounds=(0.0, 30.0, 0.0, 12.0)))
    xy = grid.cell_to_world(np.argwhere(np.ones(grid.shape, dtype=bool)))
    cells = grid.world_to_cell(xy)
    block = xy[:, 0] >= 18.0
    wall = block & (np.mod(xy[:, 0] - 18.0, 1.0) < 0.1)
    grid.log_odds[cells[block & ~wall, 0], cells[block & ~wall, 1]] = -2.0
    grid.log_odds[cells[wall, 0], cells[wall, 1]] = 3.0
    belief = goal_belief(grid, np.zeros(grid.shape, dtype=bool), GoalPrior(np.array([8.0, 6.0]), 5.4),
                         BeliefParams())
    east, _ = grid.cell_axes()
    assert belief.mass[:, east >= 18.0].sum() < 0.1
    assert belief.mass[:, east < 18.0].sum() > 0.9
