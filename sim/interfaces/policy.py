"""Our navigator as a Gymnasium policy: ``action = policy(obs)``, from the observation alone.

The policy keeps what a robot would: an occupancy grid built from the
observed laser scans at the observed odometry, and a navigation policy of
:data:`sim.navigation.policies.NAVIGATORS` fed with the observed tags (placed
in the world by the odometry; their text is the world's tag table, as a
reader's). It counts simulated time in steps of ``tick_s``, one per call.
Build it for an episode with ``env.unwrapped.navigator_policy()``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sim.experiments.trial import TrialParams, occupancy_grid, policy_params
from sim.interfaces.observation import decode_sightings
from sim.navigation.policies import Policy, make_policy
from sim.perception.laser import laser_angles
from sim.world.data import World
from sim.world.robot import RobotParams


class NavigatorPolicy:
    """The project's navigator driving through the environment's interface."""

    def __init__(self, world: World, goal: str, *, params: TrialParams, navigator: str = "paper",
                 action: str = "twist", tick_s: float = 0.1, seed: int = 0) -> None:
        self.world, self.goal, self.params, self.navigator = world, goal, params, navigator
        self.action, self.tick_s = action, tick_s
        self.robot = RobotParams()
        self.rng = np.random.default_rng(seed)
        self.grid = occupancy_grid(world, params)
        self.angles = laser_angles(params.laser)
        self.policy: Policy | None = None
        self.t = 0.0  # s of simulated time
        self.distance = 0.0  # m, from odometry
        self.last: np.ndarray | None = None

    def __call__(self, obs: dict[str, Any]) -> np.ndarray:
        """The action for this observation (one call per environment step)."""
        pose_array = np.asarray(obs["odometry"], dtype=float)
        pose = (float(pose_array[0]), float(pose_array[1]), float(pose_array[2]))
        prm = self.params
        if self.policy is None:
            self.policy = make_policy(self.navigator, self.world, self.goal, pose, policy_params(prm))
        else:
            self.t += self.tick_s
            self.distance += float(np.hypot(*(pose_array[:2] - self.last[:2])))  # type: ignore[index]
        self.last = pose_array
        self.grid.integrate(pose, self.angles, np.asarray(obs["laser"], dtype=float), prm.laser.max_range_m)
        self.policy.observe(decode_sightings(obs), t_s=self.t, distance_m=self.distance, grid=self.grid)
        v, w = self.policy.command(self.t, pose, self.grid, self.tick_s, self.rng)
        if self.policy.gave_up:
            v, w = 0.0, 0.0
        if self.action == "wheels":
            half = self.robot.wheel_separation / 2.0
            return np.array([v - w * half, v + w * half])
        return np.array([v, w])
