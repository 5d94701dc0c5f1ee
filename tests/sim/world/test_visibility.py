"""The reading rule shared by perception and the oracle."""

from __future__ import annotations

import math

import numpy as np

from sim.world.visibility import readable

RULE = {"max_range_m": 4.0, "cone_half_angle_deg": 45.0}


def test_range_cone_and_front():
    # tag at the origin facing +x
    assert readable(2.0, 0.0, 0.0, 0.0, 0.0, **RULE) is True
    assert readable(2.0, 1.9, 0.0, 0.0, 0.0, **RULE) is True  # 43.5 degrees off the normal
    assert readable(2.0, 2.1, 0.0, 0.0, 0.0, **RULE) is False  # 46.4 degrees
    assert readable(4.1, 0.0, 0.0, 0.0, 0.0, **RULE) is False  # too far
    assert readable(-2.0, 0.0, 0.0, 0.0, 0.0, **RULE) is False  # behind
    assert readable(0.0, 0.0, 0.0, 0.0, 0.0, **RULE) is False  # on the tag


def test_arrays_agree_with_numbers():
    rng = np.random.default_rng(0)
    x, y = rng.uniform(-5, 5, 500), rng.uniform(-5, 5, 500)
    theta = math.radians(30.0)
    many = readable(x, y, 0.5, -0.5, theta, **RULE)
    assert many.dtype == bool and many.shape == (500,)
    assert list(many) == [readable(a, b, 0.5, -0.5, theta, **RULE) for a, b in zip(x, y)]
    assert 0 < many.sum() < 500
