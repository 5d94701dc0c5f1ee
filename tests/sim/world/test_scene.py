"""The pybullet scene: walls from the floor plan, tags, rays, several clients."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("pybullet")

from sim.world.scene import SceneParams, build_scene  # noqa: E402
from sim.world.tag_texture import tag_png  # noqa: E402
from sim.world.walls import merge_rectangles, pool_occupancy  # noqa: E402


def test_walls_are_few_bodies_and_boxes(tiny_world, tiny_scene):
    occupied = int(tiny_world.floorplan.occupied.sum())
    assert len(tiny_scene.wall_boxes) < occupied / 50
    assert 0 < len(tiny_scene.wall_body_ids) < occupied / 50


def test_wall_boxes_cover_exactly_the_pooled_grid(tiny_world, tiny_scene):
    fp = tiny_world.floorplan
    cell = tiny_scene._pool * fp.resolution
    boxes = tiny_scene.wall_boxes
    area = np.sum((boxes[:, 1] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 2]))
    assert area == pytest.approx(tiny_scene._grid.sum() * cell ** 2)


def test_merge_rectangles_is_an_exact_disjoint_cover():
    rng = np.random.default_rng(3)
    grid = rng.random((40, 50)) < 0.3
    grid[10:30, 5:45] = True
    cover = np.zeros(grid.shape, dtype=int)
    for r0, r1, c0, c1 in merge_rectangles(grid):
        cover[r0:r1, c0:c1] += 1
    assert np.array_equal(cover, grid.astype(int))
    assert len(merge_rectangles(grid)) < grid.sum()


def test_pooling_keeps_thin_walls():
    grid = np.zeros((9, 9), dtype=bool)
    grid[:, 4] = True
    pooled = pool_occupancy(grid, 3)
    assert pooled.shape == (3, 3) and pooled[:, 1].all() and not pooled[:, [0, 2]].any()
    with pytest.raises(ValueError, match="factor"):
        pool_occupancy(grid, 0)


def test_ray_stops_at_the_inner_wall(tiny_scene):
    fractions = tiny_scene.ray_fractions(np.array([[4.0, 2.5, 1.0], [2.0, 6.5, 1.0]]),
                                         np.array([[8.0, 2.5, 1.0], [8.0, 6.5, 1.0]]))
    assert fractions[0] == pytest.approx(0.5, abs=0.02)  # wall face at x = 6.0
    assert fractions[1] == 1.0  # the corridor above the inner wall is free


def test_ray_fractions_rejects_bad_shapes(tiny_scene):
    with pytest.raises(ValueError, match="origins"):
        tiny_scene.ray_fractions(np.zeros((2, 3)), np.zeros((3, 3)))


def test_tags_hang_in_front_of_their_wall(tiny_world, tiny_scene):
    on_wall = tiny_scene.tag_poses[0]
    assert 5.95 < on_wall.x < 6.0 and on_wall.y == pytest.approx(2.5)
    assert on_wall.z == pytest.approx(tiny_world.tag_height)
    assert on_wall.theta == pytest.approx(math.pi)
    free = tiny_scene.tag_poses[1]
    assert (free.x, free.y) == pytest.approx((3.0, 6.0))
    assert set(tiny_scene.tag_body_ids) == set(tiny_world.tags)


def test_tag_texture_is_the_apriltag_of_its_id(tmp_path):
    cv2 = pytest.importorskip("cv2")
    p = SceneParams()
    image = cv2.imread(str(tag_png(7, px_per_cell=p.tag_px_per_cell, margin_cells=p.tag_margin_cells,
                                   blur_cells=p.tag_blur_cells, folder=tmp_path)), cv2.IMREAD_GRAYSCALE)
    detector = cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11))
    _, ids, _ = detector.detectMarkers(image)
    assert ids is not None and ids.ravel().tolist() == [7]


def test_scenes_are_independent_clients(tiny_world):
    first = build_scene(tiny_world)
    second = build_scene(tiny_world)
    try:
        assert first.client != second.client
        first.step(3)
        second.close()
        ray = (np.array([[4.0, 2.5, 1.0]]), np.array([[8.0, 2.5, 1.0]]))
        assert first.ray_fractions(*ray)[0] == pytest.approx(0.5, abs=0.02)
    finally:
        first.close()
        second.close()


def test_a_scene_without_looks_has_the_same_walls_and_tags(tiny_world, tiny_scene):
    bare = build_scene(tiny_world, params=SceneParams(visuals=False))
    try:
        assert bare.wall_body_ids == [] and bare.tag_body_ids == {} and bare.wall_collision_ids
        assert bare.tag_poses == tiny_scene.tag_poses
        angles = np.linspace(0, 2 * math.pi, 90, endpoint=False)
        origins = np.tile([2.0, 2.0, 0.3], (90, 1))
        ends = origins + 8.0 * np.stack([np.cos(angles), np.sin(angles), np.zeros(90)], axis=1)
        assert np.array_equal(bare.ray_fractions(origins, ends), tiny_scene.ray_fractions(origins, ends))
        from sim.perception import make_perception

        with pytest.raises(ValueError, match="visuals"):
            make_perception("camera", bare)
    finally:
        bare.close()
