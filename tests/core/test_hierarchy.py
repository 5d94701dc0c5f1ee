"""Hierarchy loading, levels, clauses and errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from abstract_map.hierarchy import Hierarchy, HierarchyError

ZOO = Path(__file__).resolve().parents[2] / "worlds" / "zoo"


def test_zoo_levels_and_clauses():
    h = Hierarchy.from_xml(ZOO / "hierarchy.xml")
    levels = h.levels()
    assert levels["Zoo"] == 3 and levels["African Safari"] == 2 and levels["Lion"] == 1
    assert h.roots() == ["Zoo"]
    assert len(h.places) == 33
    clauses = h.clauses()
    assert len(clauses) == 32
    assert ("Lion", ("African Safari",)) in [(c.figure, c.referents) for c in clauses]


def test_parent_is_one_above_its_highest_child():
    h = Hierarchy.from_nested({"Campus": {"A Block": {"Floor 1": {"Room 1": {}}}, "Shed": {}}})
    assert h.levels() == {"Campus": 4, "A Block": 3, "Floor 1": 2, "Room 1": 1, "Shed": 1}


def test_nested_round_trip():
    tree = {"Campus": {"A Block": {"Room 1": {}, "Room 2": {}}, "B Block": {}}}
    assert Hierarchy.from_nested(tree).to_nested() == tree


@pytest.mark.parametrize("xml, match", [
    ("<hierarchy><place name='Zoo'>", "malformed"),
    ("<hierarchy><place/></hierarchy>", "no name"),
    ("<hierarchy><room name='X'/></hierarchy>", "unexpected element <room>"),
    ("<hierarchy></hierarchy>", "no <place>"),
    ("<hierarchy><place name='A'><place name='B'/></place><place name='C'><place name='B'/></place></hierarchy>",
     "already in"),
])
def test_bad_hierarchy_xml(xml, match):
    with pytest.raises(HierarchyError, match=match):
        Hierarchy.from_xml_string(xml)


def test_entity_expansion_is_refused(tmp_path):
    bomb = tmp_path / "bomb.xml"
    bomb.write_text('<?xml version="1.0"?><!DOCTYPE h [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;">]>'
                    '<hierarchy><place name="&b;"/></hierarchy>')
    with pytest.raises(HierarchyError, match="bomb.xml"):
        Hierarchy.from_xml(bomb)


def test_missing_file_names_the_path(tmp_path):
    with pytest.raises(HierarchyError, match="nope.xml"):
        Hierarchy.from_xml(tmp_path / "nope.xml")


def test_cycle_is_refused():
    h = Hierarchy.from_nested({"A": {"B": {}}})
    with pytest.raises(HierarchyError, match="cycle"):
        h.add("A", "B")
