"""Laser scans against synthetic occupancy images with known geometry."""

import math

import numpy as np
import pytest

from sim.perception.laser import LaserParams, grid_caster, laser_angles, scan

RES = 0.05  # m per cell of the test images


def room_with_wall(wall_x: float = 3.0) -> tuple[np.ndarray, float, tuple[float, float]]:
    """A 10 m x 10 m image, origin (-5, -5), with one wall 0.1 m thick starting at x = wall_x."""
    n = int(10.0 / RES)
    occupied = np.zeros((n, n), dtype=bool)
    col = int(round((wall_x + 5.0) / RES))
    occupied[:, col:col + 2] = True
    return occupied, RES, (-5.0, -5.0)


def test_angles_span_the_field_of_view() -> None:
    angles = laser_angles(LaserParams())
    assert angles.shape == (181,)
    assert angles[0] == pytest.approx(-math.pi / 2)
    assert angles[-1] == pytest.approx(math.pi / 2)
    assert angles[90] == pytest.approx(0.0)


def test_full_circle_has_no_duplicate_beam() -> None:
    angles = laser_angles(LaserParams(fov_deg=360, n_beams=360))
    assert angles.shape == (360,)
    assert angles[-1] - angles[0] == pytest.approx(2 * math.pi - math.radians(1))


def test_ranges_match_a_wall_at_known_distance() -> None:
    caster = grid_caster(*room_with_wall(3.0))
    pose = (0.02, 0.1, 0.0)
    params = LaserParams(max_range_m=8.0, n_beams=181)
    ranges = scan(pose, caster, params)
    angles = laser_angles(params)
    expected = (3.0 - pose[0]) / np.cos(angles)
    hits = np.abs(angles) < math.radians(50)  # the wall is 10 m tall: these beams all hit it within 8 m
    assert np.all(np.abs(ranges[hits] - expected[hits]) <= RES)
    assert ranges[90] == pytest.approx(2.98, abs=RES)
    # Beams pointing sideways leave the 10 m image without hitting anything.
    assert ranges[0] == params.max_range_m and ranges[-1] == params.max_range_m


def test_heading_rotates_the_scan() -> None:
    n = int(10.0 / RES)
    y_centre = -5.0 + (n - 1 - np.arange(n)[:, None] + 0.5) * RES
    occupied = np.broadcast_to((y_centre > 2.0) & (y_centre < 2.1), (n, n))  # lower face at y = 2.0
    caster = grid_caster(occupied, RES, (-5.0, -5.0))
    ranges = scan((0.3, 0.0, math.pi / 2), caster, LaserParams())
    assert ranges[90] == pytest.approx(2.0, abs=RES)
    assert ranges[45] == pytest.approx(2.0 / math.cos(math.pi / 4), abs=RES)


def test_no_hit_reports_max_range() -> None:
    caster = grid_caster(np.zeros((20, 20), dtype=bool), 0.1, (0.0, 0.0))
    params = LaserParams(max_range_m=5.0, n_beams=11)
    assert np.all(scan((1.0, 1.0, 0.3), caster, params) == 5.0)


def test_noise_needs_a_generator_and_spares_no_hit_beams() -> None:
    caster = grid_caster(*room_with_wall(3.0))
    params = LaserParams(noise_std_m=0.05)
    with pytest.raises(ValueError, match="rng"):
        scan((0.0, 0.0, 0.0), caster, params)
    clean = scan((0.0, 0.0, 0.0), caster, LaserParams())
    noisy = scan((0.0, 0.0, 0.0), caster, params, np.random.default_rng(1))
    hit = clean < params.max_range_m
    assert np.all(noisy[~hit] == params.max_range_m)
    assert 0.02 < np.std(noisy[hit] - clean[hit]) < 0.08
    again = scan((0.0, 0.0, 0.0), caster, params, np.random.default_rng(1))
    assert np.array_equal(noisy, again)


def test_bad_pose_is_named() -> None:
    caster = grid_caster(np.zeros((5, 5), dtype=bool), 0.1, (0.0, 0.0))
    with pytest.raises(ValueError, match="pose"):
        scan((0.0, float("nan"), 0.0), caster)


def test_caster_returning_wrong_shape_is_rejected() -> None:
    with pytest.raises(ValueError, match="cast"):
        scan((0.0, 0.0, 0.0), lambda o, e: np.ones(3))


def test_caster_fraction_and_start_inside_obstacle() -> None:
    occupied = np.zeros((10, 10), dtype=bool)
    occupied[:, 5] = True  # x in [0.5, 0.6)
    cast = grid_caster(occupied, 0.1, (0.0, 0.0))
    origins = np.array([[0.05, 0.5], [0.55, 0.5], [0.05, 0.5]])
    ends = np.array([[1.05, 0.5], [0.95, 0.5], [0.05, 0.95]])
    fractions = cast(origins, ends)
    assert fractions[0] == pytest.approx(0.45, abs=1e-9)  # enters the wall's face at x = 0.5
    assert fractions[1] == 1.0  # starts inside the wall and leaves it
    assert fractions[2] == 1.0  # runs parallel to the wall
