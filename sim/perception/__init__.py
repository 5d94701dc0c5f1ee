"""Perception: what the robot senses: the tags it reads, and laser scans.

Tags come as :class:`Sighting` s in the world frame. Two modes share
``observe(robot) -> list[Sighting]``: ``"camera"`` renders a panoramic camera
and detects AprilTags in the images; ``"geometric"`` decides from the map
(range, reading cone, field of view, line of sight). The laser (``laser``)
casts its beams over the floor plan, and the spotter (``spotting``) reports
the tags seen from afar but not read, by where they hang. May import
``sim.world``.
"""

from __future__ import annotations

from typing import Any, Protocol

from sim.perception.camera import CameraParams, CameraPerception
from sim.perception.geometric import GeometricParams, GeometricPerception
from sim.perception.sighting import Sighting
from sim.world.robot import Robot
from sim.world.scene import Scene
from sim.world.visibility import readable

PERCEPTION_MODES: dict[str, type[CameraPerception] | type[GeometricPerception]] = {
    "camera": CameraPerception,
    "geometric": GeometricPerception,
}


class Perception(Protocol):
    """What every perception mode provides."""

    def observe(self, robot: Robot) -> list[Sighting]:
        """The tags read from the robot's camera now, one sighting per tag."""
        ...


def make_perception(name: str, scene: Scene, **kwargs: Any) -> Perception:
    """The perception mode ``name`` on ``scene``; kwargs go to its constructor (``params``, ``rng``)."""
    try:
        mode = PERCEPTION_MODES[name]
    except KeyError:
        raise ValueError(f"unknown perception mode {name!r}; known modes: {sorted(PERCEPTION_MODES)}") from None
    return mode(scene, **kwargs)


__all__ = [
    "PERCEPTION_MODES", "CameraParams", "CameraPerception", "GeometricParams", "GeometricPerception",
    "Perception", "Sighting", "make_perception", "readable",
]
