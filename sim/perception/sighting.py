"""What perception reports, and the reading rules both perception modes share.

Frames: world frame, metres, radians counter-clockwise from +x.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Sighting:
    """One tag read once: its id and the world pose of its face."""

    tag_id: int
    x: float  # m, world frame, centre of the tag
    y: float  # m, world frame
    theta: float  # rad, world frame, the tag face's outward normal projected on the floor
    range_m: float  # m, floor-plane distance from the camera to the tag
