"""``scripts/imagined_goal_worth.py``: is the imagined goal nearer the goal's label than a point anywhere?"""

from __future__ import annotations

import math

import numpy as np
import pytest

from sim.world.data import load_world
from tests.repo_files import load_file, refused_in_one_line


def load():
    return load_file("scripts/imagined_goal_worth.py", "imagined_goal_worth")


def test_the_even_distance_is_the_median_distance_to_the_nearest_label():
    script = load()
    points = np.array([[3.0, 4.0], [6.0, 8.0], [0.0, 1.0]])  # 5, 10 and 1 m from the origin
    assert script.even_distance(np.array([[0.0, 0.0]]), points) == pytest.approx(5.0)
    assert script.even_distance(np.array([[0.0, 0.0], [6.0, 9.0]]), points) == pytest.approx(1.0)


def test_points_drawn_evenly_lie_on_the_free_floor():
    script = load()
    world = load_world("zoo")
    xy = script.free_points(world, 500, np.random.default_rng(0))
    cells = world.floorplan.world_to_pixel(xy)
    assert not world.floorplan.occupied[cells[:, 0], cells[:, 1]].any()


def test_the_summary_counts_the_samples_nearer_than_an_even_point_and_the_calibration():
    script = load()
    samples = [script.Sample(0.0, "arrow", 2.0, 20.0, math.sqrt(2)),
               script.Sample(5.0, "arrow", 30.0, 20.0, 15 / math.sqrt(2)),
               script.Sample(5.0, "hierarchy", 10.0, 20.0, 10 / math.sqrt(2))]
    arrow, hierarchy = script.summary("w", samples)
    assert "arrow" in arrow and "samples    2" in arrow and "nearer  50%" in arrow
    assert "miss median  16.0 m" in arrow and "an even point  20.0 m" in arrow
    assert f"calibration {math.sqrt((1 ** 2 + 2 ** 2) / 2):4.2f}" in arrow  # z = 2 / 2 and 30 / 15
    assert "hierarchy" in hierarchy and "nearer 100%" in hierarchy and "calibration 1.00" in hierarchy
    assert script.summary("w", []) == ["w          no sample"]


def test_on_the_zoo_the_arrows_put_the_toilets_within_metres_of_their_label():
    """Before any sign the hierarchy alone places the goal; once an arrow names it the imagined goal lies within
    a few metres of its label, far nearer than a point anywhere in the zoo."""
    script = load()
    samples = script.walk_samples(load_world("zoo"), "Toilets", 5.0, 600.0, np.random.default_rng(0))
    assert samples[0].walked_m < 1.0 and samples[0].placed_by == "hierarchy"
    assert [s.walked_m for s in samples] == sorted(s.walked_m for s in samples)
    named = [s for s in samples if s.placed_by == "arrow"]
    assert named and all(s.miss_m < 5.0 < 15.0 < s.even_m for s in named)


def test_a_world_that_is_not_there_is_one_line_and_exit_2(capsys, tmp_path):
    assert "nowhere" in refused_in_one_line(load().main, ["--world", str(tmp_path / "nowhere")], capsys,
                                            "imagined_goal_worth")


def test_a_stride_that_is_not_positive_is_one_line_and_exit_2(capsys):
    assert "got 0 and 600" in refused_in_one_line(load().main, ["--world", "zoo", "--stride", "0"], capsys,
                                                  "imagined_goal_worth")
