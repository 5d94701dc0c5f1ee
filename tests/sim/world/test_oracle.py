"""The oracle: shortest path to a pose that can read the goal's label."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sim.world.oracle import OracleParams, oracle_path, readable_cells


def test_tiny_world_oracle_goes_around_nothing(tiny_world):
    # Start (2, 2); label A at (6.0, 2.5) facing -x: readable from within 4 m to its west.
    result = oracle_path(tiny_world, "A")
    assert result.tag_id == 0
    assert result.length_m == pytest.approx(0.0, abs=0.2)  # the start already reads A (4 m, in the cone)


def test_oracle_from_behind_the_wall_goes_around_it(tiny_world):
    result = oracle_path(tiny_world, "A", start=(8.5, 1.0))
    # east of the inner wall (x 6.0-6.2, y 0-5): around its top end at y = 5, then back down the west side
    assert result.path[:, 1].max() > 5.0 + 0.38 - 0.05
    end = result.path[-1]
    assert end[0] < 6.0 and math.hypot(end[0] - 6.0, end[1] - 2.5) <= 4.0 + 1e-6
    straight = math.hypot(8.5 - end[0], 1.0 - end[1])
    assert result.length_m > straight + 2.0
    steps = np.hypot(*np.diff(result.path, axis=0).T)
    assert result.length_m == pytest.approx(steps.sum())


def test_readable_cells_respect_the_cone_and_range(tiny_world):
    from sim.world.oracle import pooled_floorplan

    plan = pooled_floorplan(tiny_world, 0.05)
    mask = readable_cells(plan, tiny_world.tags[0], OracleParams())
    rows, res = plan.occupied.shape[0], plan.resolution
    cells = np.argwhere(mask)
    x = (cells[:, 1] + 0.5) * res
    y = (rows - 1 - cells[:, 0] + 0.5) * res
    assert len(cells) > 100
    assert np.all(x < 6.0)  # only in front (west) of the tag
    assert np.all(np.hypot(x - 6.0, y - 2.5) <= 4.0 + 1e-9)
    assert np.all(np.abs(np.degrees(np.arctan2(y - 2.5, 6.0 - x))) <= 45.0 + 2.0)


def test_unknown_goal_is_an_error(tiny_world):
    with pytest.raises(ValueError, match="Narnia"):
        oracle_path(tiny_world, "Narnia")
