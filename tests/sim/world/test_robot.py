"""The differential-drive robot: wheel-driven motion, speed limits, walls, odometry."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("pybullet")

from sim.world.robot import Robot, RobotParams  # noqa: E402


@pytest.fixture()
def robot(tiny_scene):
    bot = Robot(tiny_scene)
    yield bot
    import pybullet as p

    p.removeBody(bot.body, physicsClientId=tiny_scene.client)


def _drive(scene, robot, v, w, seconds):
    robot.command(v, w)
    scene.step(round(seconds / scene.time_step))


def test_pose_moves_when_commanded(tiny_scene, robot):
    robot.reset(2.0, 2.0, 0.0)
    tiny_scene.step(10)
    _drive(tiny_scene, robot, 0.3, 0.0, 2.0)
    x, y, theta = robot.true_pose()
    assert 2.4 < x < 2.65 and y == pytest.approx(2.0, abs=0.05) and abs(theta) < 0.05
    assert robot.pose() == pytest.approx((x, y, theta))


def test_speed_is_clamped(tiny_scene, robot):
    robot.reset(1.0, 6.8, 0.0)
    tiny_scene.step(10)
    seconds = 4.0
    assert robot.command(2.0, 0.0) == (0.4, 0.0)
    tiny_scene.step(round(seconds / tiny_scene.time_step))
    distance = robot.true_pose()[0] - 1.0
    assert 0.3 * seconds < distance <= 0.4 * seconds * 1.02


def test_turn_rate_is_clamped(tiny_scene, robot):
    robot.reset(2.0, 2.5, 0.0)
    tiny_scene.step(10)
    _drive(tiny_scene, robot, 0.0, 5.0, 2.0)
    turned = robot.true_pose()[2]
    assert 0.5 < turned <= 0.4 * 2.0 * 1.05


def test_walls_stop_the_robot(tiny_scene, robot):
    robot.reset(3.0, 2.5, 0.0)
    tiny_scene.step(10)
    for _ in range(12):
        _drive(tiny_scene, robot, 0.4, 0.0, 1.0)
        assert robot.true_pose()[0] < 6.0 - robot.params.length / 2 + 0.02
    x, y, _ = robot.true_pose()
    assert x > 5.5  # it reached the wall and pushes against it
    assert robot.camera_pose()[2] == pytest.approx(1.3, abs=0.05)  # still upright


def test_rays_do_not_hit_the_robot(tiny_scene, robot):
    robot.reset(3.0, 6.5, 0.0)
    tiny_scene.step(10)
    fraction = tiny_scene.ray_fractions(np.array([[1.0, 6.5, 0.4]]), np.array([[5.0, 6.5, 0.4]]))
    assert fraction[0] == 1.0


def test_camera_pose_and_size(tiny_scene, robot):
    robot.reset(2.0, 3.0, 1.0)
    tiny_scene.step(10)
    x, y, z, yaw = robot.camera_pose()
    assert (x, y, yaw) == pytest.approx((2.0, 3.0, 1.0), abs=0.02)
    assert z == pytest.approx(1.3, abs=0.02)
    assert robot.radius == pytest.approx(0.38, abs=0.01)


def test_odometry_drift_is_reproducible(tiny_scene):
    import pybullet as p

    params = RobotParams(odometry_noise_m=0.05, odometry_noise_rad=0.05)
    runs = []
    for _ in range(2):
        bot = Robot(tiny_scene, params=params, rng=np.random.default_rng(11))
        bot.reset(2.0, 2.0, 0.0)
        poses = []
        for _ in range(4):
            _drive(tiny_scene, bot, 0.3, 0.2, 0.5)
            poses.append(bot.pose())
        drift = np.array(poses[-1]) - np.array(bot.true_pose())
        runs.append(np.array(poses))
        p.removeBody(bot.body, physicsClientId=tiny_scene.client)
        assert 0 < np.abs(drift).max() < 0.5
    assert np.allclose(runs[0], runs[1], atol=1e-3)
    with pytest.raises(ValueError, match="rng"):
        Robot(tiny_scene, params=params)


def test_command_rejects_non_finite(tiny_scene, robot):
    with pytest.raises(ValueError, match="nan"):
        robot.command(math.nan, 0.0)
