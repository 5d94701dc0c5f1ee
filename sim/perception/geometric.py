"""Geometric perception: which tags the robot could read, from the map alone (no images).

A tag is read iff it is within range and the camera is inside its reading
cone (see :func:`~sim.perception.sighting.readable`), it is inside the
camera's horizontal field of view, and a ray from the camera to the tag is not
blocked by walls. These rules are applied where the scene hung the tag
(``scene.tag_poses``: on the wall's face, up to ~0.2 m in front of the world
file's pose when the floor plan draws a tag inside its wall), as the camera
sees it; the sighting reports the world file's (true) pose. Frames: world
frame, metres, radians counter-clockwise from +x.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim.perception.sighting import Sighting
from sim.world.robot import Robot
from sim.world.scene import Scene
from sim.world.visibility import readable


@dataclass(frozen=True)
class GeometricParams:
    """Reading rules and optional Gaussian noise of geometric perception."""

    max_range_m: float = 4.0  # m, floor-plane distance camera -> tag
    cone_half_angle_deg: float = 45.0  # deg, half-angle of the reading cone about the tag normal
    fov_deg: float = 360.0  # deg, horizontal field of view of the camera, centred on its yaw
    noise_m: float = 0.0  # m, std of the Gaussian noise added to x and y
    noise_rad: float = 0.0  # rad, std of the Gaussian noise added to theta
    ray_stop_m: float = 0.05  # m, occlusion rays end this far in front of the tag face


class GeometricPerception:
    """Reads tags by geometry: true tag poses (plus optional noise) from the world."""

    renders = False  # needs no looks: the scene may be built without them (SceneParams.visuals=False)

    def __init__(self, scene: Scene, params: GeometricParams | None = None, *,
                 rng: np.random.Generator | None = None) -> None:
        self.scene = scene
        self.params = params or GeometricParams()
        if (self.params.noise_m > 0 or self.params.noise_rad > 0) and rng is None:
            raise ValueError("GeometricPerception: noise is set but no rng (np.random.Generator) was given")
        self._rng = rng

    def observe(self, robot: Robot) -> list[Sighting]:
        """The tags readable from the robot's camera now, one sighting per tag, nearest first."""
        prm = self.params
        cx, cy, cz, cyaw = robot.camera_pose()
        candidates = []
        for tag in self.scene.world.tags.values():
            face = self.scene.tag_poses[tag.id]
            if abs(face.x - cx) > prm.max_range_m or abs(face.y - cy) > prm.max_range_m:
                continue  # out of range: the cheap test first (readable() would say no too)
            if not readable(cx, cy, face.x, face.y, face.theta,
                            max_range_m=prm.max_range_m, cone_half_angle_deg=prm.cone_half_angle_deg):
                continue
            bearing = math.atan2(face.y - cy, face.x - cx)
            if prm.fov_deg < 360.0 and abs(math.remainder(bearing - cyaw, math.tau)) > math.radians(prm.fov_deg) / 2:
                continue
            candidates.append(tag)
        if not candidates:
            return []
        ends = []
        for tag in candidates:
            face = self.scene.tag_poses[tag.id]
            ends.append([face.x + prm.ray_stop_m * math.cos(face.theta),
                         face.y + prm.ray_stop_m * math.sin(face.theta), face.z])
        origins = np.tile([cx, cy, cz], (len(candidates), 1))
        clear = self.scene.ray_fractions(origins, np.array(ends)) >= 1.0
        sightings = []
        for tag, visible in zip(candidates, clear):
            if not visible:
                continue
            x, y, theta = tag.x, tag.y, tag.theta
            if self._rng is not None and (prm.noise_m > 0 or prm.noise_rad > 0):
                x += self._rng.normal() * prm.noise_m
                y += self._rng.normal() * prm.noise_m
                theta = math.remainder(theta + self._rng.normal() * prm.noise_rad, math.tau)
            face = self.scene.tag_poses[tag.id]
            sightings.append(Sighting(tag.id, x, y, theta, math.hypot(face.x - cx, face.y - cy)))
        return sorted(sightings, key=lambda s: s.range_m)
