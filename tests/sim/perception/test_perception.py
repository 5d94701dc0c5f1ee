"""Perception: the camera reads rendered AprilTags like the real study; geometric mode agrees."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("pybullet")
pytest.importorskip("cv2")

from sim.perception import (  # noqa: E402
    PERCEPTION_MODES,
    GeometricParams,
    GeometricPerception,
    Sighting,
    make_perception,
    readable,
)
from sim.world.robot import Robot  # noqa: E402

MODES = sorted(PERCEPTION_MODES)


def facing(x: float, y: float, target_x: float, target_y: float) -> tuple[float, float, float]:
    """A robot pose at (x, y) m heading towards (target_x, target_y) m."""
    return x, y, math.atan2(target_y - y, target_x - x)


# (name, robot pose, tag id, must it be read?)
CASES = [
    ("straight at 2 m", (4.0, 2.5, 0.0), 0, True),
    ("oblique 30 deg at 2 m", facing(6.0 - 2 * math.cos(math.radians(30)), 2.5 + 2 * math.sin(math.radians(30)),
                                     6.0, 2.5), 0, True),
    ("behind a free-standing tag", (3.0, 4.0, math.pi / 2), 1, False),
    ("wall tag from the wrong side", (4.5, 0.8, 0.0), 3, False),
    ("oblique 70 deg at 2 m", facing(6.0 - 2 * math.cos(math.radians(70)), 2.5 + 2 * math.sin(math.radians(70)),
                                     6.0, 2.5), 0, False),
    ("past 4 m", (1.0, 2.5, 0.0), 0, False),
    ("through a wall", (4.5, 2.5, 0.0), 2, False),
]


@pytest.fixture(scope="module")
def robot(tiny_scene):
    return Robot(tiny_scene)


@pytest.fixture(scope="module")
def perceptions(tiny_scene):
    return {name: make_perception(name, tiny_scene) for name in MODES}


def _observe(scene, robot, perception, pose):
    robot.reset(*pose)
    scene.step(5)
    return {s.tag_id: s for s in perception.observe(robot)}


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_reading_rules(tiny_world, tiny_scene, robot, perceptions, mode, case):
    _, pose, tag_id, expected = case
    seen = _observe(tiny_scene, robot, perceptions[mode], pose)
    assert (tag_id in seen) == expected, f"{mode}: saw {sorted(seen)}"
    if expected:
        tag, sighting = tiny_world.tags[tag_id], seen[tag_id]
        assert math.hypot(sighting.x - tag.x, sighting.y - tag.y) < 0.1
        assert abs(math.degrees(math.remainder(sighting.theta - tag.theta, math.tau))) < 5.0
        camera = robot.camera_pose()
        assert sighting.range_m == pytest.approx(math.hypot(sighting.x - camera[0], sighting.y - camera[1]), abs=0.05)


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_modes_agree(tiny_scene, robot, perceptions, case):
    pose = case[1]
    seen = {mode: set(_observe(tiny_scene, robot, perceptions[mode], pose)) for mode in MODES}
    assert seen["camera"] == seen["geometric"]


def test_camera_sees_tag_behind_the_robot(tiny_world, tiny_scene, robot, perceptions):
    seen = _observe(tiny_scene, robot, perceptions["camera"], (4.0, 2.5, math.pi))
    assert set(seen) == {0}


def test_geometric_field_of_view_and_noise(tiny_scene, robot):
    narrow = GeometricPerception(tiny_scene, GeometricParams(fov_deg=90.0))
    assert _observe(tiny_scene, robot, narrow, (4.0, 2.5, math.pi)) == {}
    assert set(_observe(tiny_scene, robot, narrow, (4.0, 2.5, 0.0))) == {0}
    params = GeometricParams(noise_m=0.05, noise_rad=0.05)
    draws = [_observe(tiny_scene, robot, GeometricPerception(tiny_scene, params, rng=np.random.default_rng(5)),
                      (4.0, 2.5, 0.0))[0] for _ in range(2)]
    assert draws[0] == draws[1] and (draws[0].x, draws[0].y) != (6.0, 2.5)
    with pytest.raises(ValueError, match="rng"):
        GeometricPerception(tiny_scene, params)


def test_unknown_mode_is_named(tiny_scene):
    with pytest.raises(ValueError, match="'nope'.*camera.*geometric"):
        make_perception("nope", tiny_scene)


def test_readable_rules():
    assert readable(0.0, 0.0, 2.0, 0.0, math.pi, max_range_m=4.0, cone_half_angle_deg=45.0)
    assert not readable(0.0, 0.0, 2.0, 0.0, 0.0, max_range_m=4.0, cone_half_angle_deg=45.0)
    assert not readable(0.0, 0.0, 5.0, 0.0, math.pi, max_range_m=4.0, cone_half_angle_deg=45.0)
    assert not readable(0.0, 2.1, 2.0, 0.0, math.pi, max_range_m=4.0, cone_half_angle_deg=45.0)
    with pytest.raises(AttributeError):
        Sighting(1, 0.0, 0.0, 0.0, 1.0).x = 2.0  # type: ignore[misc]


def test_skipping_empty_views_changes_nothing(tiny_scene, robot):
    from sim.perception import CameraParams, CameraPerception

    full = CameraPerception(tiny_scene, CameraParams(skip_empty_views=False))
    fast = CameraPerception(tiny_scene)
    for _, pose, _, _ in CASES:
        assert _observe(tiny_scene, robot, full, pose) == _observe(tiny_scene, robot, fast, pose)


def test_views_skip_tags_whose_edges_walls_hide(tiny_scene):
    from sim.perception import CameraPerception

    camera = CameraPerception(tiny_scene)
    poses = tiny_scene.tag_poses
    assert camera._edges_hidden(4.5, 2.5, [poses[2], poses[0]]) == [True, False]  # tag 2 is through a wall


def test_camera_ignores_tags_of_other_worlds(tiny_scene, robot, perceptions):
    import pybullet as p

    cid = tiny_scene.client
    stranger = p.createMultiBody(0, -1, tiny_scene.tag_visual_shape(), basePosition=[5.98, 3.4, 1.1],
                                 baseOrientation=p.getQuaternionFromEuler([0, 0, math.pi]), physicsClientId=cid)
    p.changeVisualShape(stranger, -1, textureUniqueId=tiny_scene.texture(30), physicsClientId=cid)
    try:
        camera = perceptions["camera"]
        robot.reset(4.0, 2.5, 0.0)
        tiny_scene.step(5)
        x, y, z, yaw = robot.camera_pose()
        rendered = camera.render(x, y, z, yaw, [0])[0]
        assert {d.tag_id for d in camera.detect(rendered, x, y, z, yaw)} == {0, 30}
        assert {s.tag_id for s in camera.observe(robot)} == {0}
    finally:
        p.removeBody(stranger, physicsClientId=cid)


def test_upright_fit_recovers_a_tag_pose(perceptions):
    camera = perceptions["camera"]
    truth = np.array([0.3, -0.1, 2.5, 0.4])  # centre (camera frame, m) and turn (rad)
    pixels = camera._project(truth[None, :])[0].reshape(4, 2)
    t, angle, error = camera._upright(pixels, truth[:3] + [0.1, 0.05, -0.2], truth[3] - 0.2)
    assert np.allclose(t, truth[:3], atol=1e-6) and angle == pytest.approx(truth[3], abs=1e-6)
    assert error < 1e-12


def test_corner_refinement_moves_corners_onto_the_square():
    from sim.perception.camera import refine_corners

    size, scale = 64, 8  # px, and samples per pixel along each axis
    corners = np.array([[20.3, 18.6], [44.7, 19.4], [43.9, 43.8], [19.5, 43.1]])  # (u, v) px, pixel centres at integers
    axis = (np.arange(size * scale) + 0.5) / scale - 0.5
    u, v = np.meshgrid(axis, axis)
    inside = np.ones_like(u, dtype=bool)
    for a, b in zip(corners, np.roll(corners, -1, axis=0)):  # a convex quad: inside every edge's half-plane
        inside &= (b[0] - a[0]) * (v - a[1]) - (b[1] - a[1]) * (u - a[0]) >= 0
    grey = np.where(inside, 0.0, 255.0).reshape(size, scale, size, scale).mean(axis=(1, 3)).astype(np.float32)
    given = corners + [[0.5, -0.4], [-0.5, 0.4], [0.4, 0.5], [-0.4, -0.5]]  # a detector's corners, 0.64 px off
    refined = refine_corners(grey, given)
    assert np.linalg.norm(refined - corners, axis=1).max() < 0.25
    assert np.array_equal(refine_corners(np.full_like(grey, 128.0), corners), corners)  # no edge: kept as given
