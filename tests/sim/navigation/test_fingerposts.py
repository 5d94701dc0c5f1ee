"""The fingerpost test: an arrow into a wall beside its reader says the building's arrows point at places."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sim.mapping.occupancy import OccupancyGrid, OccupancyParams, mapped_plan
from sim.navigation.fingerposts import PostParams, PostTest, runs_into_wall


def wall_at_south() -> OccupancyGrid:
    """10 m x 6 m, mapped free, with a mapped wall along y = 1.0 .. 1.2 m (a sign hangs on its north face)."""
    grid = OccupancyGrid(OccupancyParams(resolution_m=0.1, bounds=(0.0, 10.0, 0.0, 6.0)))
    grid.log_odds[:] = -2.0
    xy = grid.cell_to_world(np.argwhere(np.ones(grid.shape, dtype=bool)))
    wall = (xy[:, 1] >= 1.0) & (xy[:, 1] < 1.2)
    cells = grid.world_to_cell(xy[wall])
    grid.log_odds[cells[:, 0], cells[:, 1]] = 3.0
    return grid


SIGN = (5.0, 1.2)  # m, on the wall's north face, facing north (pi / 2)


def test_an_arrow_back_into_the_signs_wall_runs_into_it_and_one_along_the_wall_or_ahead_does_not():
    grid, params = wall_at_south(), PostParams()
    north = math.pi / 2
    assert runs_into_wall(grid, SIGN, north, -math.pi / 2, params)  # DOWN: through the sign's own wall
    assert runs_into_wall(grid, SIGN, north, -math.pi / 4, params)  # down and right: the wall 1.4 m on
    assert not runs_into_wall(grid, SIGN, north, 0.0, params)  # RIGHT: along the wall, a metre off it
    assert not runs_into_wall(grid, SIGN, north, north, params)  # UP: into the open floor
    facing_the_wall = (5.0, 3.2)  # a sign 2 m north of the wall, facing south: its reader 1 m from the wall
    assert not runs_into_wall(grid, facing_the_wall, -north, -north, params)  # UP across a corridor: no mark
    assert runs_into_wall(grid, (5.0, 1.0), -north, north, params)  # DOWN through its own wall from the south


def test_each_sign_counts_once_and_moves_the_odds_by_its_likelihood_ratio():
    grid, params = wall_at_south(), PostParams()
    test = PostTest(params)
    assert test.chance == pytest.approx(params.prior)
    test.judge(grid, [("#1", SIGN, math.pi / 2, [0.0, math.pi / 2])])  # a way sign: both arrows run clear
    way = params.prior / (1 - params.prior) * (1 - params.blocked_post) / (1 - params.blocked_way)
    assert test.chance == pytest.approx(way / (1 + way))
    test.judge(grid, [("#1", SIGN, math.pi / 2, [-math.pi / 2]), ("#2", SIGN, math.pi / 2, [-math.pi / 2])])
    assert test.judged == {"#1": False, "#2": True}  # #1 was judged already; #2 points into the wall
    both = way * params.blocked_post / params.blocked_way
    assert test.chance == pytest.approx(both / (1 + both))
    assert PostTest(PostParams(prior=1.0), {"#2": False}).chance == 1.0  # the paper's reading whatever is seen


def test_guided_reads_a_wayfinding_building_as_one_and_the_same_building_with_fingerposts_as_the_other(tmp_path):
    """Every sign of a small office read on its mapped plan: with wayfinding signs the guided search gives the
    abstract map's point and the arrows' bearings a small share; with fingerposts (the same building,
    ``arrows=bearing``) nearly all, and its prior is then all but the model's own."""
    from sim.experiments.trial import TrialParams, policy_params
    from sim.navigation.belief import MixedPrior
    from sim.navigation.policies import EvenPriorPolicy, GuidedPolicy
    from sim.world.data import load_world
    from sim.world.generator import generated_world

    chances = {}
    for arrows in ("way", "bearing"):
        world = load_world(generated_world(3, style="office", size="small", arrows=arrows, root=tmp_path))
        goal = sorted(world.goals)[0]
        policy = GuidedPolicy(world, goal, world.start, policy_params(TrialParams()))
        assert policy.bearing_share() == pytest.approx(0.5) and isinstance(policy.goal_prior(), MixedPrior)
        for tag in world.tags.values():
            if tag.kind == "sign":
                policy.nav.model.observe_tag(tag.id, tag.text, (tag.x, tag.y, tag.theta), kind="sign")
        policy.posts.judge(mapped_plan(world.floorplan), policy._signs_read())
        assert len(policy.posts.judged) == sum(t.kind == "sign" and "$" in t.text for t in world.tags.values())
        chances[arrows] = policy.bearing_share()
        prior = policy.goal_prior()
        assert prior.parts[0][0] == pytest.approx(chances[arrows])
        even = EvenPriorPolicy(world, goal, world.start, policy_params(TrialParams()))
        assert even.bearing_share() == 0.0 and not isinstance(even.goal_prior(), MixedPrior)
    assert chances["way"] < 0.2 and chances["bearing"] > 0.9
