"""The viewpoint and guided navigators end to end: the tiny world and a small generated building."""

from __future__ import annotations

import pytest

from sim.experiments.trial import run_trial
from sim.navigation.policies import NAVIGATORS

SEARCHERS = ["viewpoint", "guided"]  # the navigators that keep a belief or evidence layer and a swept layer


def test_searchers_are_navigators_beside_paper():
    assert {"paper", *SEARCHERS} <= set(NAVIGATORS)


@pytest.mark.parametrize("navigator", SEARCHERS)
def test_searcher_finds_the_tiny_goal_and_records_belief_and_swept_space(tiny_world, navigator):
    result = run_trial(tiny_world, "A", seed=1, perception="geometric", navigator=navigator, record=True)
    assert result.success, result.reason
    assert result.distance_m < 3.0
    assert {"belief", "swept"} <= set(result.frames[-1].layers)
    assert result.frames[-1].layers["belief"].shape == result.frames[-1].grid.shape


@pytest.mark.parametrize("navigator", SEARCHERS)
def test_searcher_finds_a_goal_in_a_small_generated_building(tmp_path, navigator):
    from sim.world.data import load_world
    from sim.world.generator import generated_world
    from sim.world.oracle import oracle_path

    world = load_world(generated_world(3, style="office", size="small", signage="complete", root=tmp_path))
    oracle = {goal: oracle_path(world, goal).length_m for goal in world.goals}
    goal = min(oracle, key=oracle.get)  # the nearest goal: a short smoke run
    result = run_trial(world, goal, perception="geometric", navigator=navigator)
    assert result.success, result.reason
    assert result.distance_m < 5.0 * oracle[goal] + 10.0  # no wandering: a loose bound


@pytest.mark.slow
@pytest.mark.parametrize("style", ["hospital", "museum"])
def test_viewpoint_finds_every_goal_of_a_generated_building(tmp_path, style):
    from sim.world.data import load_world
    from sim.world.generator import generated_world

    world = load_world(generated_world(4, style=style, size="small", signage="sparse", root=tmp_path))
    for goal in sorted(world.goals):
        result = run_trial(world, goal, perception="geometric", navigator="viewpoint")
        assert result.success, (goal, result.reason)

