"""Cue text to clauses: every zoo line, the grammar's forms, and its errors."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from abstract_map.clauses import Locational, Relational
from abstract_map.grammar import Anchor, CueError, parse_cue

ZOO = Path(__file__).resolve().parents[2] / "worlds" / "zoo"
SIGN = Anchor("#9", 1.0, 2.0, math.pi / 2)


def arrows(clauses):
    """(place, direction in whole degrees within [0, 360)) of each arrow clause."""
    return [(c.toponym, round(math.degrees(c.direction)) % 360) for c in clauses if isinstance(c, Locational)]


def rels(clauses):
    return [(c.preposition, c.figure, c.referents, c.context) for c in clauses if isinstance(c, Relational)]


# Expected clauses of every sign in the zoo: arrows as (place, direction deg), phrases as tuples.
ZOO_SIGNS = {
    3: ([("Information desk", 180), ("Bird Aviary", 180), ("African Safari", 180), ("Photo gallery", 0),
         ("Snake House", 0), ("Arctic Frontier", 0), ("Outback Adventure", 0), ("Toilets", 90)], []),
    4: ([("Information desk", 90)], [("past", "African Safari", ("Information desk",), "#4")]),
    8: ([("Eagle", -90), ("Cockatoo", -90), ("Kingfisher", -90), ("Owl", 180), ("Parrot", 180)],
        [("past", "African Safari", ("Owl",), "#8")]),
    15: ([("Giraffe", 89), ("Cheetah", -1), ("Leopard", -1)],
         [("past", "Lion", ("Giraffe",), "#15"), ("past", "Leopard", ("Hyena",), "#15")]),
    21: ([("Cheetah", 180), ("Leopard", 180), ("Hyena", 180)],
         [("right of", "Lion", ("Giraffe",), "#21"), ("past", "Giraffe", ("Hyena",), "#21")]),
    29: ([("Photo gallery", 90), ("Arctic Frontier", 90), ("Outback Adventure", 0), ("Snake House", -90)], []),
    36: ([("Cobra", 0)], [("near", "Cobra", ("#36",), "#36"), ("past", "Anaconda", ("Cobra",), "#36")]),
}


def zoo_tags():
    return {t["id"]: t for t in json.loads((ZOO / "tags.json").read_text())["tags"]}


@pytest.mark.parametrize("tag_id", sorted(ZOO_SIGNS))
def test_every_zoo_sign_parses_to_the_expected_clauses(tag_id):
    tag = zoo_tags()[tag_id]
    anchor = Anchor(f"#{tag_id}", tag["x_m"], tag["y_m"], math.radians(tag["theta_deg"]))
    clauses = parse_cue(tag["text"], anchor)
    want_arrows, want_rels = ZOO_SIGNS[tag_id]
    assert arrows(clauses) == [(n, d % 360) for n, d in want_arrows]
    assert rels(clauses) == want_rels
    assert len(clauses) == len(want_arrows) + len(want_rels)


def test_every_zoo_label_is_one_label_clause_behind_its_tag():
    labels = [t for t in zoo_tags().values() if t["kind"] == "label"]
    assert len(labels) == 32
    for tag in labels:
        anchor = Anchor(f"#{tag['id']}", tag["x_m"], tag["y_m"], math.radians(tag["theta_deg"]))
        (clause,) = parse_cue(tag["text"], anchor)
        assert clause == Locational("label", tag["text"], f"#{tag['id']}",
                                    math.remainder(math.radians(tag["theta_deg"]) + math.pi, math.tau))


def test_backslash_n_separates_lines_like_a_newline():
    assert parse_cue("$UP$ A\\nB is past C", SIGN) == parse_cue("$UP$ A\nB is past C", SIGN)


def test_arrow_with_and_without_space():
    assert parse_cue("$UP$Cheetah, Leopard and Hyena", SIGN) == parse_cue("$UP$ Cheetah, Leopard, Hyena", SIGN)
    assert len(parse_cue("$UP$Cheetah, Leopard and Hyena", SIGN)) == 3


def test_many_figures_and_referents_with_context():
    clauses = parse_cue("from the Foyer, Cheetah, Leopard and Hyena are past the Giraffe")
    assert rels(clauses) == [("past", n, ("Giraffe",), "Foyer") for n in ("Cheetah", "Leopard", "Hyena")]
    assert rels(parse_cue("The Lion is past the Giraffe, from the Foyer")) == [("past", "Lion", ("Giraffe",), "Foyer")]


def test_phrase_on_a_sign_without_context_uses_the_sign():
    assert rels(parse_cue("The Lion is past the Giraffe", SIGN)) == [("past", "Lion", ("Giraffe",), "#9")]
    assert rels(parse_cue("The Lion is past the Giraffe")) == [("past", "Lion", ("Giraffe",), None)]


def test_between_takes_two_referents():
    assert rels(parse_cue("Isla's office is between the entryway and printer")) == [
        ("between", "Isla's office", ("entryway", "printer"), None)]
    with pytest.raises(CueError, match="between"):
        parse_cue("A is between B")


def test_articles_are_not_part_of_names_but_capital_a_is():
    assert rels(parse_cue("The Lion is in the African Safari")) == [("in", "Lion", ("African Safari",), None)]
    assert rels(parse_cue("Room 1 is in A Block")) == [("in", "Room 1", ("A Block",), None)]
    assert rels(parse_cue("a printer is near an office")) == [("near", "printer", ("office",), None)]


def test_label_text_is_the_place_name():
    (clause,) = parse_cue("The Bird Aviary", SIGN)
    assert clause.toponym == "Bird Aviary" and clause.kind == "label"


@pytest.mark.parametrize("text, match", [
    ("", "empty"),
    ("   ", "empty"),
    ("The Lion is under the Giraffe", "unknown preposition 'under'"),
    ("$SIDEWAYS$ Lion", "unknown arrow"),
    ("$LEFT$", "points to no place"),
    ("Lion Giraffe\nsomething odd", "line 1"),
    ("The Cobra is near here", None),
])
def test_bad_cues_raise_naming_the_line(text, match):
    if match is None:  # "here" without a sign pose
        with pytest.raises(CueError, match="here"):
            parse_cue(text)
        return
    with pytest.raises(CueError, match=match):
        parse_cue(text, SIGN, kind="sign" if text.strip() else None)


def test_arrow_without_a_pose_is_an_error():
    with pytest.raises(CueError, match="pose of the sign"):
        parse_cue("$LEFT$ A")


def test_nan_anchor_is_an_error():
    with pytest.raises(CueError, match="finite"):
        Anchor("#1", float("nan"), 0.0, 0.0)


def test_a_place_is_named_by_its_surest_cue():
    """A phrase (figure or referent) beats an arrow, which beats no cue at all; names compare canonically."""
    from abstract_map.clauses import named_by

    sign = parse_cue("$LEFT$ Lion, Bird Aviary\nThe Lion is past the Giraffe", SIGN, kind="sign")
    assert named_by(sign, "Lion") == "phrase"
    assert named_by(sign, "Giraffe") == "phrase"
    assert named_by(sign, "Bird Aviary") == "arrow"
    assert named_by(sign, "Toilets") == "hierarchy"
    assert named_by([], "Lion") == "hierarchy"
    assert named_by(sign, "bird aviary", canonical=str.lower) == "arrow"
    assert named_by(parse_cue("Kingfisher", SIGN, kind="label"), "Kingfisher") == "hierarchy"  # a label is no cue
