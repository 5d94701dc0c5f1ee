"""What perception reports, and the reading rules both perception modes share.

Frames: world frame, metres, radians counter-clockwise from +x.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Sighting:
    """One tag read once: its id and the world pose of its face."""

    tag_id: int
    x: float  # m, world frame, centre of the tag
    y: float  # m, world frame
    theta: float  # rad, world frame, the tag face's outward normal projected on the floor
    range_m: float  # m, floor-plane distance from the camera to the tag


def readable(camera_x: float, camera_y: float, tag_x: float, tag_y: float, tag_theta: float, *,
             max_range_m: float, cone_half_angle_deg: float) -> bool:
    """Whether a tag at (tag_x, tag_y) facing tag_theta may be read from a camera at (camera_x, camera_y).

    The rules of the original study: within ``max_range_m`` (floor-plane
    distance) and in front of the tag, inside the cone of half-angle
    ``cone_half_angle_deg`` about its normal. Occlusion is not checked here.
    """
    dx, dy = camera_x - tag_x, camera_y - tag_y
    distance = math.hypot(dx, dy)
    if distance > max_range_m:
        return False
    if distance == 0.0:
        return False
    off_normal = abs(math.remainder(math.atan2(dy, dx) - tag_theta, math.tau))
    return off_normal <= math.radians(cone_half_angle_deg)
