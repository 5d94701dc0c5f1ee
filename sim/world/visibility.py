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
    distance = np.hypot(np.subtract(camera_x, tag_x), np.subtract(camera_y, tag_y))
    off = off_normal(camera_x, camera_y, tag_x, tag_y, tag_theta)
    ok = (distance <= max_range_m) & (distance > 0.0) & (off <= math.radians(cone_half_angle_deg))
    return bool(ok) if np.ndim(ok) == 0 else ok


def off_normal(camera_x: ArrayLike, camera_y: ArrayLike, tag_x: ArrayLike, tag_y: ArrayLike,
               tag_theta: ArrayLike) -> Any:
    """The angle (rad, in [0, pi]) between a tag's facing and the direction from the tag to the camera: 0 square in
    front of it, pi/2 edge-on, pi behind it. Numbers or arrays that broadcast, as :func:`readable` takes."""
    dx, dy = np.subtract(camera_x, tag_x), np.subtract(camera_y, tag_y)
    return np.abs(np.remainder(np.arctan2(dy, dx) - tag_theta + np.pi, 2.0 * np.pi) - np.pi)
