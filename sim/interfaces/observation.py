"""The environment's observation: its space, and the trial's state encoded in it (and decoded back).

Frames: "world" is the building's frame; "robot" is the robot's base frame
(x ahead, y to its left), metres and radians counter-clockwise. Poses are
float64 so an agent can rebuild world coordinates to the simulator's precision.

- ``laser``: ranges (m) of every beam, right to left (``sim.perception.laser.laser_angles``); no hit = max range
- ``tags``: the tags read this step, nearest first, in ``slots`` fixed slots: ``id`` (the AprilTag id, 0 when
  empty), ``pose`` (x, y, facing of the tag's face in the robot frame; zeros when empty), ``valid`` (1 = filled)
- ``odometry``: the robot's pose (x, y, heading) in the world frame, as its odometry has it
- ``goal``: where the abstract map imagines the goal now, (x, y) in the robot frame
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np
from gymnasium import spaces

from sim.perception.laser import LaserParams
from sim.perception.sighting import Sighting

MAX_TAG_ID = 586  # AprilTag 36h11 has 587 codes
REACH_M = 1000.0  # m, bound of every position in the observation: buildings are far smaller; farther goals are clipped

Pose = tuple[float, float, float]


def to_frame(pose: Pose, x: float, y: float, theta: float) -> Pose:
    """The world pose (x, y, theta) seen from ``pose`` (world): the same pose in that frame."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    dx, dy = x - pose[0], y - pose[1]
    return c * dx + s * dy, -s * dx + c * dy, math.remainder(theta - pose[2], math.tau)


def from_frame(pose: Pose, x: float, y: float, theta: float) -> Pose:
    """A pose (x, y, theta) in the frame of ``pose`` (world), back in the world frame."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return pose[0] + c * x - s * y, pose[1] + s * x + c * y, math.remainder(theta + pose[2], math.tau)


@dataclass(frozen=True)
class Observation:
    """The layout of the observation."""

    slots: int  # tags reported per step
    laser: LaserParams

    def space(self) -> spaces.Dict:
        k, reach = self.slots, REACH_M
        pose_low = np.tile([-reach, -reach, -math.pi], (k, 1))
        return spaces.Dict({
            "laser": spaces.Box(0.0, self.laser.max_range_m, (self.laser.n_beams,), np.float64),
            "tags": spaces.Dict({
                "id": spaces.Box(0, MAX_TAG_ID, (k,), np.int64),
                "pose": spaces.Box(pose_low, -pose_low, (k, 3), np.float64),
                "valid": spaces.MultiBinary(k),
            }),
            "odometry": spaces.Box(np.array([-reach, -reach, -math.pi]), np.array([reach, reach, math.pi]), (3,),
                                   np.float64),
            "goal": spaces.Box(-reach, reach, (2,), np.float64),
        })

    def encode(self, *, scan: np.ndarray, sightings: Iterable[Sighting], true_pose: Pose, odometry: Pose,
               goal_xy: tuple[float, float]) -> dict[str, Any]:
        """The observation: tags relative to the robot's true pose (what its camera measured), the goal
        relative to its odometry (where its map puts the goal)."""
        ids = np.zeros(self.slots, np.int64)
        poses = np.zeros((self.slots, 3))
        valid = np.zeros(self.slots, np.int8)
        for i, s in enumerate(list(sightings)[: self.slots]):
            ids[i], poses[i], valid[i] = s.tag_id, to_frame(true_pose, s.x, s.y, s.theta), 1
        gx, gy, _ = to_frame(odometry, goal_xy[0], goal_xy[1], 0.0)
        return {
            "laser": np.clip(np.asarray(scan, dtype=np.float64), 0.0, self.laser.max_range_m),
            "tags": {"id": ids, "pose": poses, "valid": valid},
            "odometry": np.array([odometry[0], odometry[1], math.remainder(odometry[2], math.tau)]),
            "goal": np.clip([gx, gy], -REACH_M, REACH_M),
        }


def decode_sightings(obs: dict[str, Any]) -> list[Sighting]:
    """The tags of an observation back in the world frame, placed by the observation's odometry."""
    pose = tuple(float(v) for v in obs["odometry"])
    tags = obs["tags"]
    found = []
    for tag_id, (x, y, theta), valid in zip(tags["id"], tags["pose"], tags["valid"]):
        if valid:
            wx, wy, wt = from_frame(pose, float(x), float(y), float(theta))  # type: ignore[arg-type]
            found.append(Sighting(int(tag_id), wx, wy, wt, math.hypot(float(x), float(y))))
    return found
