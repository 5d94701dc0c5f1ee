"""Settled geometry of every preposition, arrow and label."""

from __future__ import annotations

import math

import numpy as np
import pytest

from .helpers import angle_at, make_map, settle

NORTH, SOUTH = math.pi / 2, -math.pi / 2


def sign_and_label(model, phrase: str):
    """A label for B at (0, 6) facing the sign (B settles ~2 m behind it), and a sign at the origin facing +y."""
    model.observe_tag(2, "B", (0.0, 6.0, SOUTH))
    model.observe_tag(1, phrase, (0.0, 0.0, NORTH))
    settle(model)
    sign = model.fixed["#1"].xy
    return sign, model.position("B"), model.position("A")


@pytest.mark.parametrize("word", ["past", "after", "beyond"])
def test_past_puts_figure_beyond_referent(word):
    model = make_map()
    sign, b, a = sign_and_label(model, f"A is {word} B")
    assert abs(abs(angle_at(b, sign, a)) - 180.0) < 15.0
    assert a[1] > b[1]


@pytest.mark.parametrize("word", ["before", "towards", "toward"])
def test_before_puts_figure_between_reader_and_referent(word):
    model = make_map()
    sign, b, a = sign_and_label(model, f"A is {word} B")
    assert abs(abs(angle_at(a, sign, b)) - 180.0) < 15.0
    assert sign[1] < a[1] < b[1]


def test_left_of_is_the_readers_left():
    model = make_map()
    sign, b, a = sign_and_label(model, "A is left of B")
    # Reader at the sign facing B (north): left is west, the angle at B from sign to A is -90.
    assert abs(angle_at(b, sign, a) + 90.0) < 15.0
    assert a[0] < b[0] - 1.0


def test_right_of_is_the_readers_right():
    model = make_map()
    sign, b, a = sign_and_label(model, "A is right of B")
    assert abs(angle_at(b, sign, a) - 90.0) < 15.0
    assert a[0] > b[0] + 1.0


@pytest.mark.parametrize("word", ["beside", "by", "near", "with", "next to"])
def test_near_holds_half_a_unit(word):
    model = make_map()
    _, b, a = sign_and_label(model, f"A is {word} B")
    # half a unit at the level-1 scale of 4 m
    assert np.hypot(*(a - b)) == pytest.approx(2.0, abs=0.6)


def test_between_puts_figure_between_referents():
    model = make_map()
    model.observe_tag(2, "B", (-6.0, 5.0, 0.0))
    model.observe_tag(3, "C", (6.0, 5.0, math.pi))
    model.observe_tag(1, "A is between B and C", (0.0, 0.0, NORTH))
    settle(model)
    a, b, c = model.position("A"), model.position("B"), model.position("C")
    assert abs(abs(angle_at(a, b, c)) - 180.0) < 15.0
    assert b[0] < a[0] < c[0]


def test_near_here_means_the_sign_and_behind_it():
    model = make_map()
    model.observe_tag(1, "The A is near here", (3.0, 4.0, NORTH))
    settle(model)
    a = model.position("A")
    # half a unit at the sign scale of 8 m, behind the sign's face (it faces +y)
    assert np.hypot(*(a - np.array([3.0, 4.0]))) == pytest.approx(4.0, abs=1.0)
    assert a[1] < 4.0 - 2.0


@pytest.mark.parametrize("arrow, direction", [("LEFT", (1, 0)), ("RIGHT", (-1, 0)), ("UP", (0, -1)),
                                               ("DOWN", (0, 1))])
def test_arrows_on_a_sign_facing_north(arrow, direction):
    model = make_map(start=(0.0, 10.0, -math.pi / 2))
    model.observe_tag(1, f"${arrow}$ A", (0.0, 0.0, NORTH))
    settle(model)
    a = model.position("A")
    bearing = math.degrees(math.atan2(a[1], a[0]))
    expected = math.degrees(math.atan2(direction[1], direction[0]))
    assert abs(math.remainder(math.radians(bearing - expected), math.tau)) < math.radians(15)
    assert np.hypot(*a) > 4.0


def test_label_puts_the_place_behind_its_tag():
    model = make_map()
    model.observe_tag(7, "C", (5.0, 1.0, math.pi))  # faces -x, so C lies at +x
    settle(model)
    c = model.position("C")
    assert c[0] == pytest.approx(7.0, abs=0.3)
    assert c[1] == pytest.approx(1.0, abs=0.3)
    assert model.is_observed("C") and not model.is_observed("A")


def test_in_clause_extends_the_hierarchy():
    model = make_map()
    model.observe_tag(1, "The Annex is in Campus\nLab is in Annex", (0.0, 0.0, NORTH))
    settle(model)
    assert model.hierarchy.parent["Annex"] == "Campus"
    assert model.hierarchy.parent["Lab"] == "Annex"
    assert model.levels()["Annex"] == 2 and model.levels()["Campus"] == 3
    assert np.hypot(*(model.position("Annex") - model.position("Campus"))) < 40.0


def test_initial_model_lies_ahead_of_the_robot():
    model = make_map(start=(0.0, 0.0, 0.0))  # facing +x
    settle(model)
    for place in ["Campus", "A", "B", "C", "D"]:
        assert model.position(place)[0] > 0.0


def test_settle_reports_not_settled_at_the_cap():
    from dataclasses import replace

    model = make_map()
    settle(model)
    model.params = replace(model.params, dynamics=replace(model.params.dynamics, max_iterations=3))
    model.observe_tag(1, "$LEFT$ A", (0.0, 0.0, NORTH))
    report = model.settle()
    assert not report.settled and report.iterations == 3
