"""Spotting: where tags hang that the robot can see but not yet read.

A person sees a sign or a door plate from across a hall long before they can
read it, and walks over to read it. The spotter reports the tags seen to be
there: within ``range_m`` (the laser's 8 m), inside a cone of
``cone_half_angle_deg`` about the tag's normal (a plate seen at 75 degrees is
a quarter of its width: still a plate, no longer legible), with a clear line
of sight. A spot carries the tag's pose and nothing of what it says: reading
stays the perception's job (:mod:`sim.perception.geometric`,
:mod:`sim.perception.camera`). The rule is geometric in both perception modes,
as the laser is: what a camera would need to tell a plate from a picture on
the wall at 8 m is not modelled. Frames: world frame, metres, radians
counter-clockwise from +x.
"""

from __future__ import annotations

from dataclasses import dataclass

from sim.perception.geometric import GeometricParams, GeometricPerception
from sim.world.robot import Robot
from sim.world.scene import Scene


@dataclass(frozen=True)
class SpotParams:
    """When a tag is seen to be there, unread."""

    range_m: float = 8.0  # m, floor-plane distance camera -> tag: the laser's range, twice the reading range
    cone_half_angle_deg: float = 75.0  # deg about the tag's normal: foreshortened to a quarter, still a plate


@dataclass(frozen=True)
class Spot:
    """A tag seen to hang here; what it says is unknown until it is read."""

    x: float  # m, world frame, centre of the tag
    y: float  # m, world frame
    theta: float  # rad, world frame, the face's outward normal
    range_m: float  # m, floor-plane distance from the camera


class Spotter:
    """The tags seen from the robot's camera now (any kind, unread), by the geometric rule above."""

    def __init__(self, scene: Scene, params: SpotParams | None = None) -> None:
        self.params = params or SpotParams()
        self._eye = GeometricPerception(scene, GeometricParams(max_range_m=self.params.range_m,
                                                               cone_half_angle_deg=self.params.cone_half_angle_deg))

    def spot(self, robot: Robot) -> list[Spot]:
        """Every tag seen now, nearest first: where it hangs, not what it says."""
        return [Spot(s.x, s.y, s.theta, s.range_m) for s in self._eye.observe(robot)]
