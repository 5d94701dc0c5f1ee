"""Cue-by-cue resolution gives what resolving from scratch gives, and spring hashes are computed once."""

from __future__ import annotations

import pickle
import sys
from pathlib import Path

import numpy as np

from abstract_map.clauses import Relational
from abstract_map.dynamics import ComplexPositions, SpringIndex
from abstract_map.forces import forces_on
from abstract_map.hierarchy import Hierarchy
from abstract_map.model import AbstractMap, spring_changes
from abstract_map.placement import Resolved
from abstract_map.resolution import LooseGroups, SpringField
from abstract_map.scales import learn_scales, natural_lengths
from abstract_map.springs import Spring, springs_from_clauses
from abstract_map.values import GrowingFold, RememberedHash

from .helpers import walked

sys.path.append(str(Path(__file__).resolve().parents[2] / "benchmarks"))
import campus  # noqa: E402


def from_scratch(model: AbstractMap) -> tuple[list[Spring], list[float]]:
    """The model's springs and natural lengths, computed from every clause with nothing remembered."""
    clauses = springs_from_clauses(model.clauses(), model._anchor_kind,
                                   {"between_angle": model.params.between_angle})
    springs = model.springs()
    assert springs[:len(clauses)] == clauses
    levels = model.levels()
    learned = learn_scales(springs, levels, model.observed_positions().get)
    return springs, natural_lengths(springs, levels, learned, model.params.scales, model.exploration_factor)


def test_resolving_cue_by_cue_matches_resolving_from_scratch():
    walk = campus.generate(150)
    model = AbstractMap.from_hierarchy(Hierarchy.from_nested(walk.tree), walk.start)
    for i, (tag, text, pose) in enumerate(walk.cues[:40]):
        model.observe_tag(tag, text, pose)
        if i == 20:  # a level added: every scale key may change, so resolution starts again
            model.add_clauses([Relational("in", "Campus", ("Campus annex",))])
        if i == 30:
            model.bump_exploration()
        springs, lengths = from_scratch(model)
        resolved = model.resolved_springs()
        assert [(r.kind, r.ends, r.stiffness) for r in resolved] == [(s.kind, s.ends, s.stiffness) for s in springs]
        expected = [length if s.kind == "distance" else s.value for s, length in zip(springs, lengths)]
        assert [r.value for r in resolved] == expected  # exactly: the same products in the same order
    assert any(model.observed_positions().get(p) is not None for p in walk.truth)


def test_loose_groups_follow_the_places_order_and_count_the_held_roots():
    springs = [Spring("distance", ("a", "b"), 1.0, 1.0), Spring("distance", ("c", "#7"), 1.0, 1.0, "sign"),
               Spring("distance", ("d", "e"), 1.0, 1.0)]
    loose = LooseGroups()
    assert loose(["e", "d", "c", "b", "a", "f"], springs, held=[]) == ["e", "b", "f"]
    assert loose(["e", "d", "c", "b", "a", "f"], springs, held=["a"]) == ["e", "f"]
    springs.append(Spring("relative_angle", ("f", "a", "d"), 1.0, 1.0))  # grows: ties f and d's group to a
    assert loose(["e", "d", "c", "b", "a", "f"], springs, held=["a"]) == []
    assert loose(["e", "d", "c", "b", "a", "f"], springs[1:], held=[]) == ["e", "b"]  # not a growth: starts again


def test_a_growing_fold_folds_only_what_was_added_and_starts_again_otherwise():
    seen: list[list[int]] = []
    fold = GrowingFold[int, list[int]](list, lambda state, items: (seen.append(list(items)), state.extend(items)))
    assert fold([1, 2]) == [1, 2]
    assert fold([1, 2, 3]) == [1, 2, 3]
    assert fold([9, 2, 3]) == [9, 2, 3]
    assert seen == [[1, 2], [3], [9, 2, 3]]


def test_springs_keep_the_hash_they_were_made_with():
    assert Spring.__hash__ is RememberedHash.__hash__
    assert Resolved.__hash__ is RememberedHash.__hash__
    spring = Resolved("distance", ("a", "b"), 2.0, 0.5)
    assert hash(spring) == hash(Resolved("distance", ("a", "b"), 2.0, 0.5))
    assert spring == Resolved("distance", ("a", "b"), 2.0, 0.5) and np.isfinite(spring.value)


def test_a_pickled_model_goes_on_settling_exactly_as_the_original():
    model, walk = walked(10, 150, settled=False)
    copy = pickle.loads(pickle.dumps(model))
    for tag, text, pose in walk.cues[10:20]:
        for m in (model, copy):
            m.observe_tag(tag, text, pose)
            m.settle()
    assert model.positions.keys() == copy.positions.keys()
    assert all(np.array_equal(model.positions[p], copy.positions[p]) for p in model.positions)


def test_the_spring_field_gives_each_mass_the_net_force_its_own_springs_give():
    model, _ = walked(25, 150, settled=False)
    rng = np.random.default_rng(3)
    for name in model.positions:  # away from rest, so that every spring pulls
        model.positions[name] = model.positions[name] + rng.normal(0.0, 2.0, 2)
    springs = model.resolved_springs()
    index = SpringIndex(springs)
    where = ComplexPositions(model.positions, {n: f.xy for n, f in model.fixed.items()})
    names = list(model.positions)
    params = model.params.dynamics
    around = [s for s in index.around(names) for _ in range(index.count[s])]
    expected = forces_on(names, around, where, [index.length(s, params.angle_length) for s in around],
                         expand=[False] * len(names), centre=None, expansion=0.0, law="constant",
                         core=params.core)
    field = SpringField()
    field.prepare(model._cached("clause springs", model._springs_of_clauses), springs, index, params.angle_length)
    net = field.around(names, expand=[False] * len(names), centre=None, expansion=0.0, law="constant",
                       core=params.core)
    got = net(np.array([where[n] for n in net.slots], dtype=complex))
    assert np.median(np.abs(expected)) > 0.01  # not at rest: the comparison means something
    assert np.allclose(got, expected, rtol=1e-9, atol=1e-12)
    some = names[::7]
    net = field.around(some, expand=[False] * len(some), centre=None, expansion=0.0, law="constant",
                       core=params.core)
    assert np.allclose(net(np.array([where[n] for n in net.slots], dtype=complex)), expected[::7], rtol=1e-9,
                       atol=1e-12)



def test_spring_changes_finds_what_was_added_and_removed_position_by_position():
    a, b, c, d = (Resolved("distance", (x, "Z"), 1.0, 0.1) for x in "abcd")
    b2 = Resolved("distance", ("b", "Z"), 2.0, 0.1)  # b re-scaled
    old = [a, b, c]
    assert spring_changes(old, list(old), set(old)) == ([], [])
    assert spring_changes(old, [a, b2, c, d], set(old)) == ([b2, d], [b])
    assert spring_changes(old, [a, c], set(old)) == ([], [b])  # a spring gone: the rest move up a place
    equal_copy = Resolved("distance", ("c", "Z"), 1.0, 0.1)  # made anew but equal: no change
    assert spring_changes(old, [a, b, equal_copy], set(old)) == ([], [])
    assert spring_changes(old, [a, b, c, a], set(old)) is None  # a spring twice
    assert spring_changes(old, [a, b2, c, b2], set(old)) is None


def test_the_spring_field_keeps_each_angle_springs_l_as_a_fresh_field_gives_it():
    model, walk = walked(12, 150, settled=False)
    for tag, text, pose in walk.cues[12:30]:  # labels among them re-scale signs' springs
        model.observe_tag(tag, text, pose)
        model.settle()
        fresh = SpringField()
        fresh.prepare(model._cached("clause springs", model._springs_of_clauses), model.resolved_springs(),
                      SpringIndex(model.resolved_springs()), model.params.dynamics.angle_length)
        assert np.array_equal(model._field._arrays[4], fresh._arrays[4])
        assert np.array_equal(model._field._arrays[2], fresh._arrays[2])
