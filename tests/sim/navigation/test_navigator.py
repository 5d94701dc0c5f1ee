"""The navigator's decisions, without a simulator."""

from __future__ import annotations

import numpy as np
import pytest

from sim.navigation.navigator import Navigator
from sim.perception.sighting import Sighting


def sighting(world, tag_id: int) -> Sighting:
    tag = world.tags[tag_id]
    return Sighting(tag_id, tag.x, tag.y, tag.theta, 2.0)


def test_starts_with_the_goal_imagined_ahead(tiny_world):
    nav = Navigator.start(tiny_world, "A", tiny_world.start)
    target = nav.target()
    assert target[0] > tiny_world.start[0]  # the start faces +x
    x0, x1, y0, y1 = tiny_world.floorplan.extent
    assert x0 < target[0] < x1 and y0 < target[1] < y1  # clamped into the map


def test_a_sign_moves_the_goal_and_its_label_ends_the_trial(tiny_world):
    nav = Navigator.start(tiny_world, "A", tiny_world.start)
    before = nav.target()
    assert nav.observe([sighting(tiny_world, 2)], t_s=1.0, distance_m=0.5, explored_centre=lambda: (2.0, 2.0))
    assert [c.tag_id for c in nav.cues] == [2] and not nav.succeeded
    assert not np.allclose(before, nav.target())
    # the same sign again changes nothing worth a settle
    assert not nav.observe([sighting(tiny_world, 2)], t_s=2.0, distance_m=0.6, explored_centre=lambda: None)
    nav.observe([sighting(tiny_world, 0)], t_s=3.0, distance_m=1.0, explored_centre=lambda: None)
    assert nav.succeeded and nav.model.is_observed("A")


def test_a_label_read_records_how_far_the_model_missed_its_place(tiny_world):
    nav = Navigator.start(tiny_world, "A", tiny_world.start)
    imagined = nav.model.position("A")
    tag = tiny_world.tags[0]
    nav.observe([sighting(tiny_world, 0)], t_s=1.0, distance_m=0.5, explored_centre=lambda: None)
    assert nav.misses_m == [pytest.approx(float(np.hypot(imagined[0] - tag.x, imagined[1] - tag.y)))]
    nav.observe([sighting(tiny_world, 0)], t_s=2.0, distance_m=0.6, explored_centre=lambda: None)
    assert len(nav.misses_m) == 1  # a place already observed is no prediction


def test_empty_and_unknown_tags_are_ignored(tiny_world):
    nav = Navigator.start(tiny_world, "A", tiny_world.start)
    assert not nav.observe([sighting(tiny_world, 3), Sighting(99, 0.0, 0.0, 0.0, 1.0)], t_s=0.0,
                           distance_m=0.0, explored_centre=lambda: None)
    assert nav.cues == []


def test_arriving_without_the_goal_bumps_until_exhausted(tiny_world):
    from sim.navigation.navigator import NavigatorParams

    nav = Navigator.start(tiny_world, "A", tiny_world.start, params=NavigatorParams(max_bumps=2))
    assert nav.arrived_without_goal((2.0, 2.0))
    assert nav.model.exploration_factor == pytest.approx(1.25)
    assert nav.arrived_without_goal((2.0, 2.0))
    assert not nav.arrived_without_goal((2.0, 2.0))
    nav.observe([sighting(tiny_world, 2)], t_s=1.0, distance_m=0.5, explored_centre=lambda: None)
    assert nav.model.exploration_factor == 1.0 and nav.bumps_in_a_row == 0


def test_unknown_goal_is_an_error(tiny_world):
    from abstract_map.model import UnknownPlaceError

    with pytest.raises(UnknownPlaceError, match="Narnia"):
        Navigator.start(tiny_world, "Narnia", tiny_world.start)


def test_a_goal_off_the_map_is_brought_back_along_the_line_from_the_robot():
    from sim.navigation.navigator import clip_segment

    low, high = np.array([0.0, 0.0]), np.array([10.0, 8.0])
    assert np.allclose(clip_segment(np.array([2.0, 2.0]), np.array([4.0, 14.0]), low, high), [3.0, 8.0])
    assert np.allclose(clip_segment(np.array([2.0, 2.0]), np.array([5.0, 5.0]), low, high), [5.0, 5.0])
    assert np.allclose(clip_segment(np.array([9.0, 1.0]), np.array([13.0, -3.0]), low, high), [10.0, 0.0])
