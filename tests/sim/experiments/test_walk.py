"""Where a walk went: the moments it came near the goal's label and saw it, on the tiny world.

The tiny world's label A hangs at (6.0, 2.5) m on the inner wall's west face, facing -x; the wall runs from
y = 0 to 5 m at x = 6.0-6.2 m (tests/sim/conftest.py).
"""

from __future__ import annotations

import numpy as np
import pytest

from sim.experiments.walk import PHASES, WalkMarks, WalkParams, phase_means, phases, point_at, walk_marks
from sim.perception.spotting import SpotParams


def walk(*corners: tuple[float, float], step_m: float = 0.05) -> tuple[np.ndarray, float]:
    """A trajectory (rows t, x, y, theta) along straight legs through ``corners`` (m), and its length (m)."""
    points = [np.asarray(corners[0], dtype=float)]
    for a, b in zip(corners, corners[1:]):
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        n = max(1, int(np.ceil(np.hypot(*(b - a)) / step_m)))
        points += [a + (b - a) * k / n for k in range(1, n + 1)]
    xy = np.array(points)
    length = float(np.hypot(*np.diff(xy, axis=0).T).sum())
    return np.column_stack([np.arange(len(xy)) * 0.4, xy, np.zeros(len(xy))]), length


def test_a_walk_round_the_wall_comes_near_before_it_sees_the_label(tiny_world):
    # North up the east side (the wall hides the label), west along the top, south on the label's side.
    trajectory, length = walk((8.5, 1.0), (8.5, 6.5), (3.0, 6.5), (3.0, 2.5))
    marks = walk_marks(tiny_world, "A", trajectory, length, params=WalkParams(near_m=3.0))
    # Near: 3 m from the reading cone's edge (x + y = 8.5 m, west of the wall) at x = 6.24 m on the top leg.
    assert marks.near_at_m == pytest.approx(5.5 + 2.26, abs=0.4)
    # Seen: 75 degrees off the label's normal at x = 2.5 + 4 / tan(75 deg) = 4.57 m on the top leg.
    assert marks.seen_at_m == pytest.approx(5.5 + 3.93, abs=0.4)
    far, near, seen = phases(length, marks.near_at_m, marks.seen_at_m)
    assert far + near + seen == pytest.approx(length)
    assert far == pytest.approx(marks.near_at_m) and seen == pytest.approx(length - marks.seen_at_m)


def test_a_walk_that_stays_behind_the_wall_neither_comes_near_nor_sees(tiny_world):
    trajectory, length = walk((8.5, 4.0), (8.5, 0.8))
    marks = walk_marks(tiny_world, "A", trajectory, length, params=WalkParams(near_m=3.0))
    assert marks.near_at_m is None and marks.seen_at_m is None
    assert phases(length, None, None) == (length, 0.0, 0.0)


def test_a_narrower_spotting_rule_sees_the_label_later(tiny_world):
    trajectory, length = walk((8.5, 6.5), (3.0, 6.5))
    wide = walk_marks(tiny_world, "A", trajectory, length)
    narrow = walk_marks(tiny_world, "A", trajectory, length, spot=SpotParams(cone_half_angle_deg=60.0))
    assert wide.seen_at_m is not None and narrow.seen_at_m is not None
    assert narrow.seen_at_m > wide.seen_at_m + 1.0


def test_an_empty_walk_is_never_near_and_never_sees(tiny_world):
    assert walk_marks(tiny_world, "A", np.zeros((0, 4)), 0.0) == WalkMarks(None, None)


def test_marks_are_scaled_to_the_trials_own_distance(tiny_world):
    trajectory, length = walk((8.5, 1.0), (8.5, 6.5), (3.0, 6.5))
    plain = walk_marks(tiny_world, "A", trajectory, length)
    doubled = walk_marks(tiny_world, "A", trajectory, 2 * length)
    assert doubled.seen_at_m == pytest.approx(2 * plain.seen_at_m)


def test_phases_seen_before_near_leave_no_near_phase_and_means_skip_unmarked_records():
    assert phases(30.0, 20.0, 12.0) == (12.0, 0.0, 18.0)
    assert phases(30.0, 10.0, None) == (10.0, 20.0, 0.0)
    records = [{"distance_m": 30.0, "near_at_m": 10.0, "seen_at_m": 25.0},
               {"distance_m": 10.0, "near_at_m": None, "seen_at_m": None},
               {"distance_m": 99.0}, {"distance_m": None, "near_at_m": 1.0, "seen_at_m": 1.0}]
    n, means = phase_means(records)
    assert n == 2 and len(means) == len(PHASES)
    assert means == pytest.approx([10.0, 7.5, 2.5])
    assert phase_means([{"distance_m": 5.0}]) is None


def test_a_mark_lies_where_the_robot_had_walked_that_far_in_the_trials_own_metres():
    trajectory, length = walk((0.0, 0.0), (4.0, 0.0), (4.0, 3.0))
    assert point_at(trajectory, length, 0.0) == pytest.approx((0.0, 0.0))
    assert point_at(trajectory, length, 5.0) == pytest.approx((4.0, 1.0))
    assert point_at(trajectory, 2 * length, 5.0) == pytest.approx((2.5, 0.0))  # odometry twice the path
    assert point_at(trajectory, length, 99.0) == pytest.approx((4.0, 3.0))  # past the end: the end


def test_the_picture_shows_where_the_robot_came_near_and_saw_the_label(tiny_world):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from sim.experiments.pictures import WALK_MARKS, draw_walk_marks

    trajectory, length = walk((8.5, 1.0), (8.5, 6.5), (3.0, 6.5), (3.0, 2.5))
    marks = walk_marks(tiny_world, "A", trajectory, length)
    fig, ax = plt.subplots()
    draw_walk_marks(ax, trajectory, length, {"near_at_m": marks.near_at_m, "seen_at_m": None})
    labels = [line.get_label() for line in ax.get_lines()]
    plt.close(fig)
    assert labels == [f"{WALK_MARKS[0][2]}, {marks.near_at_m:.1f} m"]  # a mark never reached is not drawn
