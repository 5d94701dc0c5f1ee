"""When a tag can be read: the reading rules of the original study, shared by perception and the oracle."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike


def readable(camera_x: ArrayLike, camera_y: ArrayLike, tag_x: ArrayLike, tag_y: ArrayLike, tag_theta: ArrayLike, *,
             max_range_m: float, cone_half_angle_deg: float) -> Any:
    """Whether a tag at (tag_x, tag_y) facing tag_theta may be read from a camera at (camera_x, camera_y).

    The rules of the original study: within ``max_range_m`` (floor-plane
    distance) and in front of the tag, inside the cone of half-angle
    ``cone_half_angle_deg`` about its normal. Occlusion is not checked here.
    Camera or tag positions (and facings) may be numbers (a bool is returned) or arrays that broadcast
    (a bool array).
    """
    dx, dy = np.subtract(camera_x, tag_x), np.subtract(camera_y, tag_y)
    distance = np.hypot(dx, dy)
    off_normal = np.abs(np.remainder(np.arctan2(dy, dx) - tag_theta + np.pi, 2.0 * np.pi) - np.pi)
    ok = (distance <= max_range_m) & (distance > 0.0) & (off_normal <= math.radians(cone_half_angle_deg))
    return bool(ok) if np.ndim(ok) == 0 else ok
