"""From clauses to springs in metres, cue after cue, redoing only what a cue changed.

A model's clauses grow at their end as cues arrive, so each step here is a
fold (:class:`values.GrowingFold`) that takes in only the clauses or springs
added since it last ran, and starts again when the list changed elsewhere
(the hierarchy changed, a cue's clauses were replaced):

- :class:`ClauseSprings`: every spring of the clauses, each once, in first-seen order;
- :class:`LooseGroups`: the groups of places no chain of springs ties to a fixed point;
- :class:`Resolver`: each spring's natural length in metres (equation 7's learned scale factors, the
  defaults, the exploration factor), with a :class:`Resolved` made anew only for a spring whose
  length changed.

Each gives exactly what its from-scratch counterpart (``springs_from_clauses``,
``learn_scales`` and ``natural_lengths``) gives, in the same order.
"""

from __future__ import annotations

from array import array
from collections.abc import Hashable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from .clauses import Clause, is_anchor
from .dynamics import SpringIndex, pair
from .forces import ANGLE_KINDS, Core, NetForce
from .params import ScaleDefaults
from .placement import Resolved
from .scales import LEARNABLE, ScaleKey, default_scale, learn_scales, scale_key
from .springs import AnchorKind, Spring, add_clause_springs
from .values import GrowingFold


class ClauseSprings:
    """Every spring of a list of clauses, each once, in first-seen order (``springs_from_clauses``)."""

    def __init__(self) -> None:
        self._made: dict[Clause, list[Spring]] = {}  # each clause's springs: its anchors' kinds never change
        self._fold = GrowingFold[Clause, dict[Spring, None]](dict, self._take)
        self.anchor_kind: AnchorKind = str
        self.flags: dict[str, bool] = {}

    def _take(self, unique: dict[Spring, None], clauses: Sequence[Clause]) -> None:
        add_clause_springs(unique, clauses, self.anchor_kind, self.flags, memo=self._made)

    def __call__(self, clauses: Sequence[Clause], anchor_kind: AnchorKind, flags: dict[str, bool]) -> list[Spring]:
        """``anchor_kind`` and ``flags`` must be the same at every call (a fixed point's kind never changes)."""
        self.anchor_kind, self.flags = anchor_kind, flags
        return list(self._fold(clauses))


@dataclass
class _Graph:
    """Springs as pairs of node numbers; every fixed point is node 0."""

    node: dict[str, int] = field(default_factory=dict)
    a: array = field(default_factory=lambda: array("q"))
    b: array = field(default_factory=lambda: array("q"))

    def number(self, name: str) -> int:
        if is_anchor(name):
            return 0
        return self.node.setdefault(name, len(self.node) + 1)


class LooseGroups:
    """The first place (in the places' order) of each group that no chain of springs ties to a fixed point."""

    def __init__(self) -> None:
        self._fold = GrowingFold[Spring, _Graph](_Graph, self._take)

    @staticmethod
    def _take(graph: _Graph, springs: Sequence[Spring]) -> None:
        for s in springs:
            first = graph.number(s.ends[0])
            for end in s.ends[1:]:
                graph.a.append(first)
                graph.b.append(graph.number(end))

    def __call__(self, places: Sequence[str], springs: Sequence[Spring], held: Iterable[str]) -> list[str]:
        """``held``: places tied to a fixed point besides by ``springs`` (the start's roots)."""
        if not places:
            return []
        graph = self._fold(springs)
        extra = {p: len(graph.node) + 1 + i for i, p in enumerate(p for p in places if p not in graph.node)}
        tied = [graph.node.get(p, extra.get(p, 0)) for p in held]
        n = len(graph.node) + 1 + len(extra)
        rows = np.concatenate([np.frombuffer(graph.a, dtype=np.int64), np.zeros(len(tied), dtype=np.int64)])
        cols = np.concatenate([np.frombuffer(graph.b, dtype=np.int64), np.array(tied, dtype=np.int64)])
        _, label = connected_components(coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n)), directed=False)
        anchor = label[0]
        firsts: dict[int, str] = {}
        for place in places:
            group = label[graph.node.get(place) or extra[place]]
            if group != anchor:
                firsts.setdefault(int(group), place)
        return list(firsts.values())


@dataclass
class _Table:
    """Per spring, what its natural value needs, appended as springs arrive (at one set of levels)."""

    springs: list[Spring] = field(default_factory=list)
    unit: array = field(default_factory=lambda: array("d"))  # model units (distance) or rad (angles)
    key: array = field(default_factory=lambda: array("q"))  # scale key number; -1 for angle springs
    label: array = field(default_factory=lambda: array("b"))  # 1: a label's length, which exploration leaves
    keys: dict[ScaleKey, int] = field(default_factory=dict)
    learnable: dict[str, list[int]] = field(default_factory=dict)  # place -> its learnable springs' positions


class Resolver:
    """Springs in model units to :class:`Resolved` springs in metres and radians (``natural_lengths`` with
    ``learn_scales``), remaking only the springs whose value changed since the last call."""

    def __init__(self) -> None:
        self._levels_version: Hashable = None
        self._levels: Mapping[str, int] = {}
        self._fold = self._new_fold()
        self._table: _Table | None = None
        self._values = np.zeros(0)
        self._out: list[Resolved] = []
        self._returned: tuple[list[Resolved], np.ndarray] | None = None  # the last list returned, its values

    def _new_fold(self) -> GrowingFold[Spring, _Table]:
        return GrowingFold[Spring, _Table](_Table, self._take)

    def _take(self, table: _Table, springs: Sequence[Spring]) -> None:
        levels = self._levels
        for s in springs:
            position = len(table.springs)
            table.springs.append(s)
            table.unit.append(s.value)
            if s.kind != "distance":
                table.key.append(-1)
                table.label.append(0)
                continue
            table.key.append(table.keys.setdefault(scale_key(s, levels), len(table.keys)))
            table.label.append(s.scale == "label")
            if s.scale in LEARNABLE:
                for end in s.ends[:2]:
                    if not is_anchor(end):
                        table.learnable.setdefault(end, []).append(position)

    def __call__(self, springs: Sequence[Spring], tail: Sequence[Spring], levels: Mapping[str, int],
                 levels_version: Hashable, observed: Mapping[str, np.ndarray], defaults: ScaleDefaults,
                 exploration: float) -> list[Resolved]:
        """The resolved ``springs`` (which mostly grow at their end from call to call), then ``tail`` (a few,
        made anew each call). ``observed``: observed positions (m) of places and fixed points;
        ``levels_version`` changes whenever ``levels`` does."""
        if levels_version != self._levels_version:
            self._levels_version, self._fold = levels_version, self._new_fold()
        self._levels = levels
        table = self._fold(springs)
        seen = sorted({i for name in observed if not is_anchor(name) for i in table.learnable.get(name, ())})
        learnable = [table.springs[i] for i in seen] + \
            [s for s in tail if s.kind == "distance" and s.scale in LEARNABLE]
        learned = learn_scales(learnable, levels, observed.get)
        tail_keys = [table.keys.setdefault(scale_key(s, levels), len(table.keys)) if s.kind == "distance" else -1
                     for s in tail]
        alpha = np.array([learned.get(k, default_scale(k, defaults)) for k in table.keys] + [1.0])
        values = self._values_of(np.frombuffer(table.key, dtype=np.int64), np.frombuffer(table.unit, dtype=float),
                                 np.frombuffer(table.label, dtype=np.int8), alpha, exploration)
        n = len(self._values) if table is self._table else 0  # the fold went on: the same springs up to n
        out = self._out[:n]
        for i in np.flatnonzero(values[:n] != self._values[:n]).tolist():
            out[i] = _resolved(table.springs[i], float(values[i]))
        out.extend(_resolved(s, float(v)) for s, v in zip(table.springs[n:], values[n:].tolist()))
        self._table, self._values, self._out = table, values, out
        ends = self._values_of(np.array(tail_keys, dtype=np.int64), np.array([s.value for s in tail], dtype=float),
                               np.array([s.scale == "label" for s in tail], dtype=np.int8), alpha, exploration)
        returned = out + [_resolved(s, float(v)) for s, v in zip(tail, ends.tolist())]
        self._returned = returned, np.concatenate([values, ends])
        return returned

    def values_of(self, resolved: list[Resolved]) -> np.ndarray | None:
        """The natural values (m or rad) of ``resolved`` as an array, if it is the list the last call returned
        (the same object); else None."""
        if self._returned is None or self._returned[0] is not resolved:
            return None
        return self._returned[1]

    @staticmethod
    def _values_of(key: np.ndarray, unit: np.ndarray, label: np.ndarray, alpha: np.ndarray,
                   exploration: float) -> np.ndarray:
        """Natural values: distance springs ``unit * alpha * exploration`` (m; labels not explored), angles as
        they are (rad)."""
        stretch = np.where(label == 1, 1.0, exploration)
        return np.where(key >= 0, unit * alpha[key] * stretch, unit)


def _resolved(spring: Spring, value: float) -> Resolved:
    return Resolved(spring.kind, spring.ends, value, spring.stiffness)


@dataclass
class _Structure:
    """The springs' kinds, ends and stiffnesses as arrays, appended as springs arrive."""

    slot: dict[str, int] = field(default_factory=dict)  # every end's slot
    kind: array = field(default_factory=lambda: array("b"))  # 0 distance, 1 global, 2 relative angle
    slots: array = field(default_factory=lambda: array("q"))  # 3 per spring (distance and global use 2)
    stiffness: array = field(default_factory=lambda: array("d"))
    incident: dict[int, list[int]] = field(default_factory=dict)  # slot -> the springs touching it
    by_pair: dict[tuple[str, str], list[int]] = field(default_factory=dict)  # pivot and turned -> angle springs
    count: int = 0

    def take(self, springs: Sequence[Spring | Resolved]) -> None:
        for s in springs:
            ends = [self.slot.setdefault(e, len(self.slot)) for e in s.ends]
            self.slots.extend(ends + [0] * (3 - len(ends)))
            for end in ends:
                self.incident.setdefault(end, []).append(self.count)
            self.kind.append(ANGLE_KINDS.get(s.kind, 0))
            if s.kind in ANGLE_KINDS:
                self.by_pair.setdefault(pair(*s.ends[-2:]), []).append(self.count)
            self.stiffness.append(s.stiffness)
            self.count += 1


class SpringField:
    """Every spring of a model as arrays, kept cue by cue, for the forces a settle needs on masses held
    still: :meth:`around` gives the springs around some masses as a ``forces.NetForce``, gathered from the
    arrays (the same force ``forces.forces_on`` builds from the springs themselves, spring by spring).
    :meth:`prepare` takes the model's springs before each settle."""

    def __init__(self) -> None:
        self._fold = GrowingFold[Spring, _Structure](_Structure, _Structure.take)
        self._slot: dict[str, int] = {}
        self._names: list[str] = []
        self._parts: tuple[_Structure, _Structure] = (_Structure(), _Structure())
        self._arrays: tuple[np.ndarray, ...] = ()
        self._lengths = np.zeros(0)  # the front springs' l (m; 0 for distance springs), as of the last prepare
        self._lengths_of: SpringIndex | None = None  # the spring index those lengths came from

    def prepare(self, front: Sequence[Spring], resolved: Sequence[Resolved], index: SpringIndex, default: float,
                values: np.ndarray | None = None) -> None:
        """``resolved``: the model's resolved springs, whose first ``len(front)`` are ``front`` resolved (the
        springs that mostly grow at their end) and the rest a few made anew each time; ``index``: the same
        springs by mass, which gives an angle spring's ``l`` (m; ``default`` when no distance spring joins
        its pivot and the place it turns); ``values``: the springs' natural values, if at hand."""
        fixed = self._fold(front)
        tail = _Structure(slot=dict(fixed.slot), count=len(front))  # the tail's own arrays and slots
        tail.take(resolved[len(front):])
        kind = np.concatenate([np.frombuffer(fixed.kind, dtype=np.int8), np.frombuffer(tail.kind, dtype=np.int8)])
        rows = np.concatenate([np.frombuffer(fixed.slots, dtype=np.int64),
                               np.frombuffer(tail.slots, dtype=np.int64)]).reshape(-1, 3)
        stiffness = np.concatenate([np.frombuffer(fixed.stiffness), np.frombuffer(tail.stiffness)])
        value = np.array([s.value for s in resolved], dtype=float) if values is None else values
        n = len(front)
        if fixed is self._parts[0] and index is self._lengths_of:  # the same springs, grown: redo what changed
            lengths = np.concatenate([self._lengths, np.zeros(n - len(self._lengths))])
            redo = [i for p in index.changed_pairs for i in fixed.by_pair.get(p, ())]
            redo += (np.flatnonzero(kind[len(self._lengths):n]) + len(self._lengths)).tolist()
        else:
            lengths, redo = np.zeros(n), np.flatnonzero(kind[:n]).tolist()
        for i in redo:
            lengths[i] = index.length(resolved[i], default)
        index.changed_pairs.clear()
        self._lengths, self._lengths_of = lengths, index
        tail_lengths = [index.length(s, default) if s.kind in ANGLE_KINDS else 0.0 for s in resolved[n:]]
        self._parts = fixed, tail
        self._slot, self._names = tail.slot, list(tail.slot)
        self._arrays = kind, rows, value, stiffness, np.concatenate([lengths, tail_lengths])

    def around(self, names: Sequence[str], *, expand: Sequence[bool], centre: complex | None, expansion: float,
               law: str, core: Core) -> NetForce:
        """The net force on ``names`` from every spring touching them (and the expansion force)."""
        kind, rows, value, stiffness, length = self._arrays
        fixed, tail = self._parts
        slots = [self._slot[n] for n in names if n in self._slot]
        mine = [i for part in (fixed, tail) for k in slots for i in part.incident.get(k, ())]
        chosen = np.unique(np.array(mine, dtype=int))
        sub = rows[chosen]
        local = {name: i for i, name in enumerate(names)}
        lookup = np.full(len(self._names) + 1, -1, dtype=int)
        for name, i in local.items():
            if name in self._slot:
                lookup[self._slot[name]] = i
        used = np.unique(sub)
        others = used[lookup[used] < 0]
        lookup[others] = len(local) + np.arange(len(others))
        slots = list(names) + [self._names[i] for i in others.tolist()]
        return NetForce.of_arrays(names, slots, kind[chosen], lookup[sub], value[chosen], stiffness[chosen],
                                  length[chosen], expand=expand, centre=centre, expansion=expansion, law=law,
                                  core=core)
