"""A GuiaBot-like differential-drive robot in a :class:`~sim.world.scene.Scene`.

Frames: world frame, metres, radians counter-clockwise from +x. The robot is
driven only through its two wheel motors (pybullet velocity control with a
torque limit), so walls stop it. Body twist commands are clamped to
``RobotParams.max_speed`` / ``max_turn``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pybullet as p

from sim.world.scene import ROBOT_GROUP, ROBOT_MASK, Scene

URDF_PATH = Path(__file__).resolve().parent / "urdf" / "guiabot.urdf"


@dataclass(frozen=True)
class RobotParams:
    """The robot's drive limits, geometry as built in ``sim/urdf/guiabot.urdf``, and odometry noise."""

    max_speed: float = 0.4  # m/s, forward/backward speed limit
    max_turn: float = 0.4  # rad/s, yaw rate limit
    wheel_radius: float = 0.10  # m, must match the URDF
    wheel_separation: float = 0.40  # m, between the wheel centres, must match the URDF
    axle_height: float = 0.10  # m, base_link origin above the floor, must match the URDF
    wheel_torque: float = 6.0  # N m, motor torque limit per wheel
    wheel_friction: float = 1.0  # Coulomb coefficient, tyres on the floor
    body_friction: float = 0.05  # Coulomb coefficient of the body and its caster spheres
    length: float = 0.59  # m, footprint along x, must match the URDF
    width: float = 0.48  # m, footprint along y, must match the URDF
    # odometry drift, a random walk added to the true pose by pose(); zero = perfect odometry
    odometry_noise_m: float = 0.0  # m per sqrt(m travelled), std of the position drift
    odometry_noise_rad: float = 0.0  # rad per sqrt(rad turned), std of the heading drift
    urdf: Path = URDF_PATH


def _yaw(quaternion: tuple[float, float, float, float]) -> float:
    """Heading (rad) of the body's x axis projected on the floor."""
    x, y, z, w = quaternion
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


class Robot:
    """The robot: drive it with :meth:`command`, then step the scene."""

    def __init__(self, scene: Scene, *, params: RobotParams | None = None,
                 rng: np.random.Generator | None = None) -> None:
        self.scene = scene
        self.params = params or RobotParams()
        if (self.params.odometry_noise_m > 0 or self.params.odometry_noise_rad > 0) and rng is None:
            raise ValueError("Robot: odometry noise is set but no rng (np.random.Generator) was given")
        self._rng = rng
        cid = scene.client
        x, y, theta = scene.world.start
        self.body = p.loadURDF(str(self.params.urdf), basePosition=[x, y, self.params.axle_height],
                               baseOrientation=p.getQuaternionFromEuler([0, 0, theta]),
                               flags=p.URDF_USE_INERTIA_FROM_FILE, physicsClientId=cid)
        joints = {p.getJointInfo(self.body, j, physicsClientId=cid)[1].decode(): j
                  for j in range(p.getNumJoints(self.body, physicsClientId=cid))}
        links = {p.getJointInfo(self.body, j, physicsClientId=cid)[12].decode(): j
                 for j in range(p.getNumJoints(self.body, physicsClientId=cid))}
        self._wheels = [joints["left_wheel_joint"], joints["right_wheel_joint"]]
        self._camera_link = links["camera_link"]
        for link in [-1, *range(p.getNumJoints(self.body, physicsClientId=cid))]:
            p.setCollisionFilterGroupMask(self.body, link, ROBOT_GROUP, ROBOT_MASK, physicsClientId=cid)
            friction = self.params.wheel_friction if link in self._wheels else self.params.body_friction
            p.changeDynamics(self.body, link, lateralFriction=friction, rollingFriction=0.0,
                             spinningFriction=0.0, physicsClientId=cid)
        # pybullet's base pose is that of the inertial frame; keep the offset to base_link
        inertial = p.getDynamicsInfo(self.body, -1, physicsClientId=cid)
        self._inertial = (tuple(inertial[3]), tuple(inertial[4]))
        self._bias = np.zeros(3)
        self._last_true = np.array([x, y, theta])
        self.command(0.0, 0.0)

    @property
    def radius(self) -> float:
        """Circumscribed radius (m) of the footprint: half its diagonal."""
        return 0.5 * math.hypot(self.params.length, self.params.width)

    def reset(self, x: float, y: float, theta: float) -> None:
        """Put the robot at rest at (x, y) m, heading theta rad; zero the odometry drift."""
        cid = self.scene.client
        position, orientation = p.multiplyTransforms([x, y, self.params.axle_height],
                                                     p.getQuaternionFromEuler([0, 0, theta]), *self._inertial)
        p.resetBasePositionAndOrientation(self.body, position, orientation, physicsClientId=cid)
        p.resetBaseVelocity(self.body, [0, 0, 0], [0, 0, 0], physicsClientId=cid)
        for joint in self._wheels:
            p.resetJointState(self.body, joint, 0.0, 0.0, physicsClientId=cid)
        self._bias = np.zeros(3)
        self._last_true = np.array([x, y, theta])
        self.command(0.0, 0.0)

    def command(self, v: float, w: float) -> tuple[float, float]:
        """Drive at body speed v (m/s, +forward) and yaw rate w (rad/s, +left), clamped to the limits.

        Returns the clamped (v, w). The wheel motors hold these until the next command.
        """
        if not (math.isfinite(v) and math.isfinite(w)):
            raise ValueError(f"Robot.command: v={v!r} and w={w!r} must be finite")
        prm = self.params
        v = min(max(v, -prm.max_speed), prm.max_speed)
        w = min(max(w, -prm.max_turn), prm.max_turn)
        half = prm.wheel_separation / 2
        targets = [(v - w * half) / prm.wheel_radius, (v + w * half) / prm.wheel_radius]
        p.setJointMotorControlArray(self.body, self._wheels, p.VELOCITY_CONTROL, targetVelocities=targets,
                                    forces=[prm.wheel_torque] * 2, physicsClientId=self.scene.client)
        return v, w

    def true_pose(self) -> tuple[float, float, float]:
        """(x m, y m, heading rad) of base_link in the world, from the simulator."""
        position, orientation = p.getBasePositionAndOrientation(self.body, physicsClientId=self.scene.client)
        position, orientation = p.multiplyTransforms(position, orientation, *p.invertTransform(*self._inertial))
        return position[0], position[1], _yaw(orientation)

    def pose(self) -> tuple[float, float, float]:
        """The odometry's pose estimate: the true pose plus a drifting bias.

        The bias is a random walk advanced at each call by the motion since the
        previous call: position steps have std ``odometry_noise_m * sqrt(d)``
        (d = distance travelled, m), heading steps ``odometry_noise_rad *
        sqrt(|turn|)`` (rad). With zero noise (the default) this is the true pose.
        """
        true = np.array(self.true_pose())
        prm = self.params
        if self._rng is not None and (prm.odometry_noise_m > 0 or prm.odometry_noise_rad > 0):
            moved = math.hypot(*(true[:2] - self._last_true[:2]))
            turned = abs(math.remainder(true[2] - self._last_true[2], math.tau))
            scale = [prm.odometry_noise_m * math.sqrt(moved)] * 2 + [prm.odometry_noise_rad * math.sqrt(turned)]
            self._bias += self._rng.normal(size=3) * np.array(scale)
        self._last_true = true
        x, y, theta = true + self._bias
        return float(x), float(y), math.remainder(float(theta), math.tau)

    def camera_pose(self) -> tuple[float, float, float, float]:
        """(x m, y m, z m, yaw rad) of the camera's optical centre in the world (true, not odometry)."""
        state = p.getLinkState(self.body, self._camera_link, computeForwardKinematics=True,
                               physicsClientId=self.scene.client)
        (x, y, z), orientation = state[4], state[5]
        return x, y, z, _yaw(orientation)

    def speed(self) -> tuple[float, float]:
        """Measured body speed (m/s along the heading) and yaw rate (rad/s)."""
        linear, angular = p.getBaseVelocity(self.body, physicsClientId=self.scene.client)
        heading = self.true_pose()[2]
        return linear[0] * math.cos(heading) + linear[1] * math.sin(heading), angular[2]
