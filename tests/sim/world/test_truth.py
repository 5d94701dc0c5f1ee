"""The truth table: one geometric test per preposition, and the arrow convention."""

from __future__ import annotations

import math

import numpy as np
import pytest

from abstract_map.hierarchy import Hierarchy
from abstract_map.prepositions import ARROWS, TABLE
from sim.world.data import Tag
from sim.world.truth import (
    TRUTH,
    Facts,
    TruthParams,
    arrow_direction,
    first_leg,
    nearest_arrow,
    phrase_verdict,
    place_positions,
    row_key,
)

HIERARCHY = Hierarchy.from_nested({"Building": {"Area": {"A": {}, "B": {}}, "Hall": {}}})


def facts(**positions: tuple[float, float]) -> Facts:
    return Facts({k: np.array(v, dtype=float) for k, v in positions.items()}, HIERARCHY, TruthParams())


def test_every_preposition_word_has_a_test():
    assert {row_key(w) for w in TABLE} == set(TRUTH)


# The reader stands at C = (0, 0) and looks north at R = (0, 10).
@pytest.mark.parametrize("word, figure, true", [
    ("past", (0, 20), True), ("beyond", (3, 18), True), ("after", (0, 5), False), ("past", (10, 10), False),
    ("before", (0, 5), True), ("towards", (0, 20), False),
    ("right of", (5, 10), True), ("right of", (-5, 10), False), ("to the right of", (5, 11), True),
    ("left of", (-5, 10), True), ("left of", (5, 10), False), ("to the left of", (0, 20), False),
    ("near", (3, 12), True), ("beside", (10, 10), False), ("next to", (0, 15.9), True), ("with", (0, 16.5), False),
])
def test_relative_prepositions_follow_the_reader(word, figure, true):
    f = facts(C=(0, 0), R=(0, 10), F=figure)
    assert (phrase_verdict(f, word, "F", ("R",), "C") is None) == true


def test_between_and_in():
    f = facts(A=(0, 0), B=(10, 0), M=(5, 1), O=(5, 8))
    assert phrase_verdict(f, "between", "M", ("A", "B"), None) is None
    assert "apart" in phrase_verdict(f, "between", "O", ("A", "B"), None)
    assert phrase_verdict(f, "in", "A", ("Area",), None) is None
    assert phrase_verdict(f, "within", "A", ("Building",), None) is None
    assert "does not put" in phrase_verdict(f, "inside", "Hall", ("Area",), None)


def test_near_here_means_behind_the_sign():
    f = facts(S=(0, 0), X=(0, -2), Y=(0, 2))
    f.facing["S"] = math.pi / 2  # the sign faces north: what is near here lies south, behind it
    assert phrase_verdict(f, "near", "X", ("S",), "S") is None
    assert "in front" in phrase_verdict(f, "near", "Y", ("S",), "S")


def test_a_place_without_a_position_is_reported():
    assert "no position" in phrase_verdict(facts(C=(0, 0), R=(0, 1)), "past", "Nowhere", ("R",), "C")


def test_positions_from_labels_and_children():
    tags = {1: Tag(1, 0.0, 0.0, math.pi / 2, "label", "A"), 2: Tag(2, 4.0, 0.0, -math.pi / 2, "label", "B")}
    pos = place_positions(HIERARCHY, tags, behind_m=1.5)
    assert np.allclose(pos["A"], (0.0, -1.5)) and np.allclose(pos["B"], (4.0, 1.5))
    assert np.allclose(pos["Area"], (2.0, 0.0))  # no label: the mean of its children
    assert "Hall" not in pos


def test_arrows_follow_prepositions_arrows():
    facing = -math.pi / 2  # the sign faces south: its reader looks north
    assert arrow_direction(facing, "UP") == pytest.approx(math.pi / 2)  # ahead of the reader
    assert abs(arrow_direction(facing, "LEFT")) == pytest.approx(math.pi)  # west
    assert arrow_direction(facing, "RIGHT") == pytest.approx(0.0)  # east
    assert arrow_direction(facing, "DOWN") == pytest.approx(facing)  # behind the reader
    for arrow, offset in ARROWS.items():
        assert nearest_arrow(facing, facing + offset + 0.3) == (arrow, pytest.approx(math.degrees(0.3)))


def test_first_leg_is_the_first_straight_stretch():
    params = TruthParams()
    path = np.array([[0, 0], [0.1, 0], [3, 0.05], [3, 5]], dtype=float)
    assert first_leg(path, None, params) == pytest.approx(0.0, abs=0.05)
    jog = np.array([[0, 0], [0.1, 0.1], [0.1, 4]], dtype=float)  # a 0.14 m jog, then north
    assert first_leg(jog, None, params) == pytest.approx(math.pi / 2, abs=0.1)
    here = np.array([[1.0, 1.0]])  # already readable: the leg points at the place
    assert first_leg(here, np.array([1.0, 3.0]), params) == pytest.approx(math.pi / 2)


def test_past_and_before_say_the_same_thing_from_either_end():
    hypothesis = pytest.importorskip("hypothesis")
    st = hypothesis.strategies
    point = st.tuples(st.floats(-50, 50), st.floats(-50, 50))

    @hypothesis.given(point, point, point)
    @hypothesis.settings(max_examples=200, deadline=None)
    def check(c, r, f):
        hypothesis.assume(len({c, r, f}) == 3)
        both = facts(C=c, R=r, F=f)
        # "F is past R" (from C) and "R is before F" (from C) are one statement
        assert (phrase_verdict(both, "past", "F", ("R",), "C") is None) == \
            (phrase_verdict(both, "before", "R", ("F",), "C") is None)
        # mirrored in x, right becomes left
        mirror = facts(C=(-c[0], c[1]), R=(-r[0], r[1]), F=(-f[0], f[1]))
        assert (phrase_verdict(both, "right of", "F", ("R",), "C") is None) == \
            (phrase_verdict(mirror, "left of", "F", ("R",), "C") is None)

    check()
