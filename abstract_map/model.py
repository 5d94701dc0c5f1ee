"""The abstract map: cues in, an imagined map of places out.

State is plain data: the hierarchy, the clauses from every cue (kept per tag,
so a tag seen again replaces rather than repeats its clauses), the fixed
points (observed tags and the start), and each place's position and velocity.
Springs, scale factors and natural lengths are derived from that state at
every :meth:`AbstractMap.settle`. World frame, metres, radians.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections import Counter
from collections.abc import Callable, Collection, Hashable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from itertools import compress, islice
from operator import is_not
from typing import Any, NamedTuple

import numpy as np

from . import errors
from .clauses import START_ANCHOR, Clause, Locational, Relational, clause_names, is_anchor, tag_anchor
from .dynamics import SpringIndex
from .dynamics import settle as run_dynamics
from .errors import CueError, ModelError, UnknownPlaceError
from .grammar import Anchor, parse_cue
from .hierarchy import Hierarchy
from .params import STIFFNESS, AbstractMapParams
from .placement import Resolved, place_new_masses
from .prepositions import LOCATIONAL, TABLE
from .resolution import ClauseSprings, LooseGroups, Resolver, SpringField
from .scales import ScaleKey, learn_scales
from .springs import Spring, clause_springs
from .values import FIELDS, GrowingFold, T, remembered

__all__ = ["AbstractMap", "FixedPoint", "Observation", "SettleReport", "UnknownPlaceError", "imagined_positions"]

FIXED_KINDS = ("label", "sign", "start")


@dataclass
class FixedPoint:
    """A fixed mass: an observed tag (mean of its sightings) or the start pose."""

    kind: str  # "label", "sign" or "start"
    x: float  # m
    y: float  # m
    theta: float  # rad, facing direction (circular mean)
    sightings: int = 1
    text: str = ""

    @property
    def xy(self) -> np.ndarray:
        return np.array([self.x, self.y])

    def add_sighting(self, x: float, y: float, theta: float) -> None:
        """Refine to the running mean of every sighting (circular mean for theta)."""
        n = self.sightings
        self.x += (x - self.x) / (n + 1)
        self.y += (y - self.y) / (n + 1)
        self.theta = math.atan2(n * math.sin(self.theta) + math.sin(theta),
                                n * math.cos(self.theta) + math.cos(theta))
        self.sightings = n + 1


class _Mentions:
    """The places clauses mention (after the hierarchy's), in first-mention order, and each label's anchors."""

    def __init__(self, places: Iterable[str]) -> None:
        self.names: dict[str, None] = dict.fromkeys(places)
        self.labels: dict[str, list[str]] = {}

    def take(self, clauses: Iterable[Clause]) -> None:
        for clause in clauses:
            if isinstance(clause, Locational) and clause.kind == "label":
                self.labels.setdefault(clause.toponym, []).append(clause.anchor)
            for name in clause_names(clause):
                if not is_anchor(name):
                    self.names.setdefault(name, None)


@dataclass(frozen=True)
class _LastSettle:
    """What a settle left for the next to compare with."""

    springs: list[Resolved]  # the model's resolved springs, in its order
    members: set[Resolved]  # the same as a set (handed from settle to settle, changed only where springs did)
    count: Counter[Resolved]  # each spring's occurrences, kept only when some spring occurs twice
    duplicates: int  # occurrences beyond the first, all springs together
    fixed: dict[str, tuple[float, float]]  # m, every fixed point
    moving: list[str]  # places left with |v| >= L_v (by a cap)

    @classmethod
    def of(cls, springs: list[Resolved], fixed: Mapping[str, FixedPoint], moving: list[str],
           members: set[Resolved] | None = None) -> _LastSettle:
        """``members``: ``set(springs)`` when already at hand."""
        members = set(springs) if members is None else members
        duplicates = len(springs) - len(members)
        return cls(springs, members, Counter(springs) if duplicates else Counter(), duplicates,
                   {n: (f.x, f.y) for n, f in fixed.items()}, moving)


class _Disturbance(NamedTuple):
    """What a settle starts from: the places it moves, those it tests first, and the springs as a set."""

    active: list[str]
    tested: list[str]
    members: set[Resolved]


def spring_changes(old: Sequence[Resolved], new: Sequence[Resolved],
                   members: Collection[Resolved]) -> tuple[list[Resolved], list[Resolved]] | None:
    """The springs ``new`` adds to ``old`` and those it removes, comparing position by position (a model's
    springs mostly keep their places from settle to settle), or None if ``new`` holds some spring twice.
    ``old`` must hold each spring once; ``members`` is ``set(old)``. Costs time in proportion to the
    positions that differ, not to the springs."""
    n = min(len(old), len(new))
    differ = list(compress(range(n), map(is_not, islice(new, n), islice(old, n))))
    fresh = dict.fromkeys([new[i] for i in differ] + list(new[n:]))
    gone = dict.fromkeys([old[i] for i in differ] + list(old[n:]))
    added = [s for s in fresh if s not in gone]
    if len(fresh) < len(differ) + len(new) - n or any(s in members for s in added):
        return None  # a spring twice: at two of the positions that differ, or also at one that does not
    return added, [s for s in gone if s not in fresh]


@dataclass(frozen=True)
class SettleReport:
    """What one settle did."""

    settled: bool
    iterations: int
    wall_s: float
    new_masses: tuple[str, ...] = ()
    stopped_by: str = ""  # why it stopped unsettled: "steps" (the step cap) or "time" (the time cap); "" if settled
    moved: int = 0  # places the settle moved (its island); every other place stayed where it was


@dataclass(frozen=True)
class Observation:
    """What observing a tag did to the model."""

    tag_id: int
    new: bool  # first sighting of this tag
    clauses: tuple[Clause, ...]


def _check_pose(pose: Iterable[float], what: str) -> tuple[float, float, float]:
    """(x m, y m, theta rad) within the ranges of :mod:`errors`, else a :class:`ModelError`."""
    return errors.pose(what, pose, error=ModelError)


@dataclass
class AbstractMap:
    """A malleable imagined map of named places, anchored at the robot's start pose."""

    hierarchy: Hierarchy
    start: tuple[float, float, float]  # x m, y m, heading rad
    params: AbstractMapParams = field(default_factory=AbstractMapParams)
    goal: str | None = None
    fixed: dict[str, FixedPoint] = field(default_factory=dict)
    cue_clauses: dict[str, list[Clause]] = field(default_factory=dict)  # per anchor name
    loose_clauses: list[Clause] = field(default_factory=list)  # clauses with no tag
    positions: dict[str, np.ndarray] = field(default_factory=dict)
    velocities: dict[str, np.ndarray] = field(default_factory=dict)
    exploration_factor: float = 1.0
    explored_centre: np.ndarray | None = None
    start_roots: list[str] = field(default_factory=list)
    # bumped by every change to the clauses or fixed points; with the hierarchy's version it keys _memo
    _version: int = field(default=0, init=False, repr=False, compare=False)
    _memo: dict[str, tuple[Hashable, Any]] = field(default_factory=dict, init=False, repr=False, compare=False)
    # the clauses' springs, loose groups and natural lengths, each redoing only what a cue changed (derived)
    _clause_springs: ClauseSprings = field(default_factory=ClauseSprings, init=False, repr=False, compare=False)
    _loose: LooseGroups = field(default_factory=LooseGroups, init=False, repr=False, compare=False)
    _resolver: Resolver = field(default_factory=Resolver, init=False, repr=False, compare=False)
    _field: SpringField = field(default_factory=SpringField, init=False, repr=False, compare=False)
    _mention_fold: tuple[Hashable, GrowingFold[Clause, _Mentions]] | None = field(default=None, init=False,
                                                                                  repr=False, compare=False)
    # what the last settle saw, to tell the next what changed, and the springs by mass (derived, not saved)
    _last_settle: _LastSettle | None = field(default=None, init=False, repr=False, compare=False)
    _index: SpringIndex = field(default_factory=SpringIndex, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not isinstance(self.hierarchy, Hierarchy):
            raise ModelError(f"hierarchy: expected a Hierarchy, got {type(self.hierarchy).__name__}")
        if not isinstance(self.params, AbstractMapParams):
            raise ModelError(f"params: expected AbstractMapParams, got {type(self.params).__name__}")
        self.start = _check_pose(self.start, "start pose")
        self.fixed.setdefault(START_ANCHOR, FixedPoint("start", *self.start, text="start"))
        if not self.start_roots:
            self.start_roots = self.hierarchy.roots() or [p for p in self.hierarchy.places
                                                          if p not in self.hierarchy.parent]
        if self.goal is not None:
            self.set_goal(self.goal)

    # -- building -----------------------------------------------------------------

    @classmethod
    def from_hierarchy(cls, hierarchy: Hierarchy, start: Iterable[float], *, goal: str | None = None,
                       params: AbstractMapParams | None = None) -> AbstractMap:
        """A model of the hierarchy alone, anchored at ``start`` = (x m, y m, heading rad)."""
        return cls(hierarchy=hierarchy, start=tuple(start), params=params or AbstractMapParams(),  # type: ignore[arg-type]
                   goal=goal)

    def _cached(self, key: str, make: Callable[[], T], *extra: object) -> T:
        """``make()``, remembered until the clauses, fixed points, hierarchy (or ``extra``) change."""
        version = (self._version, self.hierarchy.version, id(self.cue_clauses), len(self.cue_clauses),
                   id(self.loose_clauses), len(self.loose_clauses), *extra)
        return remembered(self._memo, key, version, make)

    def _changed(self) -> None:
        """Forget what was derived from the clauses and fixed points."""
        self._version += 1

    def places(self) -> list[str]:
        """Every place a cue or the hierarchy mentions, in first-mention order."""
        return list(self._cached("places", self._places))

    def _places(self) -> list[str]:
        names = dict(self._mentions().names)
        for clause in self.loose_clauses:
            names.update(dict.fromkeys(n for n in clause_names(clause) if not is_anchor(n)))
        return list(names)

    def _mentions(self) -> _Mentions:
        """The places and labels that the hierarchy and the cues' clauses mention (loose clauses aside)."""
        version = self.hierarchy.version
        if self._mention_fold is None or self._mention_fold[0] != version:  # the hierarchy's places come first
            places = list(self.hierarchy.places)
            self._mention_fold = version, GrowingFold[Clause, _Mentions](partial(_Mentions, places), _Mentions.take)
        clauses = self.clauses()
        return self._mention_fold[1](clauses[:len(clauses) - len(self.loose_clauses)])

    def clauses(self) -> list[Clause]:
        """All clauses: the hierarchy's, then each cue's, then loose ones."""
        return list(self._cached("clauses", self._clauses))

    def _clauses(self) -> list[Clause]:
        out: list[Clause] = list(self.hierarchy.clauses())
        for clauses in self.cue_clauses.values():
            out.extend(clauses)
        out.extend(self.loose_clauses)
        return out

    def _name_index(self) -> dict[str, str]:
        """Case-folded place name -> the spelling first used."""
        def make() -> dict[str, str]:
            index: dict[str, str] = {}
            for place in self.places():
                index.setdefault(place.casefold(), place)
            return index
        return self._cached("name_index", make)

    def canonical(self, name: str, index: Mapping[str, str] | None = None) -> str:
        """A known place's spelling for ``name`` (case-insensitive), else ``name`` itself."""
        if name in self.positions or is_anchor(name):
            return name
        return (index if index is not None else self._name_index()).get(name.casefold(), name)

    def _canonical_clause(self, clause: Clause, index: Mapping[str, str]) -> Clause:
        if isinstance(clause, Relational):
            context = clause.context and self.canonical(clause.context, index)
            return Relational(clause.preposition, self.canonical(clause.figure, index),
                              tuple(self.canonical(r, index) for r in clause.referents), context)
        return Locational(clause.kind, self.canonical(clause.toponym, index), clause.anchor, clause.direction)

    def check_clause(self, clause: Clause, fixed: Mapping[str, FixedPoint]) -> None:
        """Refuse a clause the model could not turn into springs (checked before anything changes)."""
        if isinstance(clause, Relational) and clause.preposition not in TABLE:
            raise CueError(f"clause {clause}: unknown preposition {clause.preposition!r}; known: {sorted(TABLE)}")
        if isinstance(clause, Locational):
            if clause.kind not in LOCATIONAL:
                raise CueError(f"clause {clause}: locational kind {clause.kind!r}; known: {sorted(LOCATIONAL)}")
            if not is_anchor(clause.anchor):
                raise CueError(f"clause {clause}: {clause.anchor!r} is not a fixed point")
            errors.number(f"clause {clause} direction", clause.direction, low=-4.0, high=4.0, error=CueError)
        for name in clause_names(clause):
            if not isinstance(name, str):
                raise CueError(f"clause {clause}: a name must be text, got {errors.show(name)}")
            if is_anchor(name):
                if name not in fixed:
                    raise CueError(f"clause {clause}: fixed point {name!r} has not been observed")
            else:
                errors.place_name(f"clause {clause}", name, error=CueError)
        try:
            clause_springs(clause, lambda anchor: fixed[anchor].kind, {"between_angle": self.params.between_angle})
        except ValueError as exc:
            raise CueError(f"{exc}; the cue is refused") from None

    def _prepare(self, clauses: Iterable[Clause], fixed: Mapping[str, FixedPoint],
                 *, skip: Iterable[Clause] = ()) -> tuple[list[Clause], list[tuple[str, str, str]]]:
        """Canonical, checked clauses and the hierarchy edges they add; changes nothing.

        Raises :class:`CueError` (or :class:`HierarchyError`) for the first clause the model
        cannot take, with the model untouched: a cue is applied whole or not at all.
        """
        index = self._name_index()
        trial = self.hierarchy.copy()
        seen = set(skip)
        out: list[Clause] = []
        edges: list[tuple[str, str, str]] = []
        for clause in clauses:
            clause = self._canonical_clause(clause, index)
            self.check_clause(clause, fixed)
            if clause in seen:
                continue
            seen.add(clause)
            if isinstance(clause, Relational) and TABLE[clause.preposition].hierarchy:
                for parent in clause.referents:
                    if not is_anchor(parent) and not is_anchor(clause.figure):
                        where = f"clause {clause}"
                        trial.add(clause.figure, parent, where=where)
                        edges.append((clause.figure, parent, where))
            out.append(clause)
        return out, edges

    def _commit_edges(self, edges: Iterable[tuple[str, str, str]]) -> None:
        for child, parent, where in edges:  # already checked on a copy: cannot fail
            self.hierarchy.add(child, parent, where=where)

    def add_clauses(self, clauses: Iterable[Clause]) -> list[Clause]:
        """Add clauses with no tag of their own (e.g. spoken directions); returns the new ones.

        "X is in Y" clauses also extend the hierarchy. A new clause resets exploration.
        The clauses are checked together first: if one is refused, none is added.
        """
        added, edges = self._prepare(list(clauses), self.fixed, skip=self.loose_clauses)
        self._commit_edges(edges)
        self.loose_clauses.extend(added)
        self._changed()
        if added:
            self.exploration_factor = 1.0
        return added

    def observe_tag(self, tag_id: int, text: str, pose: Iterable[float], *, kind: str | None = None) -> Observation:
        """A tag read at world ``pose`` = (x m, y m, theta rad, the direction its face points).

        The tag becomes a fixed mass; its text becomes clauses (``kind`` "label" or
        "sign", inferred from the text when None). Seeing the tag again moves the fixed
        mass to the mean of all sightings and re-derives its clauses, never adding
        springs twice. A first sighting resets the exploration factor to 1.
        The cue is parsed and checked completely before the model changes: a refused
        cue (:class:`CueError`, :class:`ModelError`) leaves the model exactly as it was.
        """
        tag = errors.tag_id("tag id", tag_id, error=ModelError)
        x, y, theta = _check_pose(pose, f"tag {tag} pose")
        if not isinstance(text, str):
            raise CueError(f"tag {tag}: text must be a string, got {errors.show(text)}")
        if kind is not None and kind not in ("label", "sign"):
            raise CueError(f"tag {tag}: kind {errors.show(kind)} is not 'label' or 'sign'")
        name = tag_anchor(tag)
        earlier = self.fixed.get(name)
        if earlier is None:
            first = parse_cue(text, Anchor(name, x, y, theta), kind=kind)
            kind = "label" if all(isinstance(c, Locational) and c.kind == "label" for c in first) else "sign"
            point = FixedPoint(kind, x, y, theta, text=text)
        else:
            if text != earlier.text:
                raise CueError(f"tag {tag}: text {errors.show(text)} differs from its earlier reading "
                               f"{errors.show(earlier.text)}")
            point = dataclasses.replace(earlier)
            point.add_sighting(x, y, theta)
        fixed = {**self.fixed, name: point}
        parsed = parse_cue(point.text, Anchor(name, point.x, point.y, point.theta), kind=point.kind)
        clauses, edges = self._prepare(parsed, fixed)
        # commit: nothing below can fail
        self._commit_edges(edges)
        if earlier is None:
            self.fixed[name] = point
            self.exploration_factor = 1.0
            for clause in clauses:  # reality overrides imagination: re-place newly observed places
                if isinstance(clause, Locational) and clause.kind == "label" and not self.is_observed(clause.toponym):
                    self.positions.pop(clause.toponym, None)
                    self.velocities.pop(clause.toponym, None)
        else:
            for f in dataclasses.fields(point):
                setattr(earlier, f.name, getattr(point, f.name))
        self.cue_clauses[name] = clauses
        self._changed()
        return Observation(tag, earlier is None, tuple(clauses))

    # -- reading ------------------------------------------------------------------

    def _anchor_kind(self, name: str) -> str:
        return self.fixed[name].kind

    def springs(self) -> list[Spring]:
        """Every spring of the model (the start's pull on the roots included)."""
        return list(self._cached("springs", self._springs))

    def _springs_of_clauses(self) -> list[Spring]:
        return self._clause_springs(self.clauses(), self._anchor_kind, {"between_angle": self.params.between_angle})

    def _springs(self) -> list[Spring]:
        """The clauses' springs, then the start's pull on the roots and on each loose group."""
        springs = list(self._cached("clause springs", self._springs_of_clauses))
        held = self._loose(self.places(), springs, self.start_roots)
        k = STIFFNESS[self.params.start_stiffness]
        for root in self.start_roots:
            springs.append(Spring("distance", (root, START_ANCHOR), 1.0, k, "start"))
            springs.append(Spring("global_angle", (START_ANCHOR, root), self.start[2], k))
        k = STIFFNESS[self.params.loose_stiffness]
        for first in held:
            springs.append(Spring("distance", (first, START_ANCHOR), 1.0, k, "start"))
            springs.append(Spring("global_angle", (START_ANCHOR, first), self.start[2], k))
        return springs

    def levels(self) -> dict[str, int]:
        """Hierarchy level of every place (places outside the hierarchy are leaves, 1)."""
        return dict(self._cached("levels", self._levels))

    def _levels(self) -> dict[str, int]:
        levels = self.hierarchy.levels()
        return {p: levels.get(p, 1) for p in self.places()}

    def observed_positions(self) -> dict[str, np.ndarray]:
        """Every fixed point's position, and each observed place's (the mean of its label tags)."""
        return dict(self._cached("observed", self._observed_positions))

    def _observed_positions(self) -> dict[str, np.ndarray]:
        fixed = {name: f.xy for name, f in self.fixed.items()}
        labels = self._mentions().labels
        observed = {name: fixed[a[0]] if len(a) == 1 else np.mean([fixed[n] for n in a], axis=0)
                    for name, a in labels.items()}
        observed.update(fixed)
        return observed

    def observed_position(self, name: str) -> np.ndarray | None:
        """Where a place was observed (mean of its label tags), a fixed point's position, or None."""
        xy = self._cached("observed", self._observed_positions).get(name)
        return None if xy is None else xy.copy()

    def is_observed(self, place: str) -> bool:
        """True once a label of ``place`` has been read."""
        return self.observed_position(self.canonical(place)) is not None

    def scale_factors(self) -> dict[ScaleKey, float]:
        """Learned scale factors (m per unit) by key; defaults are not listed."""
        return learn_scales(self.springs(), self.levels(), self.observed_positions().get)

    def resolved_springs(self) -> list[Resolved]:
        """Springs with natural lengths in metres and angles in radians."""
        return list(self._cached("resolved", self._resolved_springs, self.exploration_factor))

    def _resolved_springs(self) -> list[Resolved]:
        front = self._cached("clause springs", self._springs_of_clauses)
        return self._resolver(front, self._cached("springs", self._springs)[len(front):],
                              self.hierarchy.levels(), self.hierarchy.version,
                              self._cached("observed", self._observed_positions), self.params.scales,
                              self.exploration_factor)

    def position(self, place: str) -> np.ndarray:
        """Imagined position (m, world) of a place."""
        if not isinstance(place, str):
            raise UnknownPlaceError(f"place: a place name must be text, got {errors.show(place)}")
        name = self.canonical(place)
        if name not in self.positions:
            known = self.places()
            if name in known:
                raise UnknownPlaceError(f"place {place!r} has no position yet: call settle() first")
            raise UnknownPlaceError(f"place {place!r} is not mentioned by any cue or the hierarchy")
        return self.positions[name].copy()

    def set_goal(self, place: str) -> None:
        errors.place_name("goal", place, error=UnknownPlaceError)
        name = self.canonical(place)
        if name not in self.places():
            raise UnknownPlaceError(f"goal {place!r} is not mentioned by any cue or the hierarchy; "
                                    f"known places: {sorted(self.places())}")
        self.goal = name

    def goal_estimate(self) -> np.ndarray:
        """Imagined position (m, world) of the goal."""
        if self.goal is None:
            raise UnknownPlaceError("no goal set")
        return self.position(self.goal)

    # -- changing -----------------------------------------------------------------

    def bump_exploration(self) -> float:
        """The goal was not where imagined: grow imagined distances by the exploration step."""
        exploration = self.params.exploration
        grown = EXPLORATION_LAWS[exploration.law](self.exploration_factor, exploration.step)
        self.exploration_factor = min(grown, exploration.max_factor)
        return self.exploration_factor

    def set_explored_centre(self, xy: Iterable[float] | None) -> None:
        """Centre (m, world) of explored free space; the expansion force pushes away from it."""
        if xy is None:
            self.explored_centre = None
            return
        self.explored_centre = np.array(errors.point("explored centre", xy, error=ModelError))

    def _disturbed(self, springs: list[Resolved], new: list[str], fixed: Mapping[str, FixedPoint]) -> _Disturbance:
        """Bring the spring index up to date, and say what a settle starts from (before new places are placed).

        The first settle moves every place. After it: the new places and those a capped settle left moving
        (|v| >= L_v) move; the ends of springs added, removed or changed, and of springs to fixed points that
        moved, since the last settle are tested, and move if they fail Algorithm 1's acceleration test."""
        last = self._last_settle
        changes = None if last is None or last.duplicates else spring_changes(last.springs, springs, last.members)
        if changes is None:  # the first settle, or a spring twice: count them all
            members = set(springs)
            self._index = SpringIndex(springs)
            if last is None:
                return _Disturbance(self.places(), [], members)
            changed: Iterable[Resolved] = sorted((Counter(springs) - last.count) + (last.count - Counter(springs)),
                                                 key=FIELDS)
        else:
            added, removed = changes
            self._index.update(added, removed)
            members = last.members
            members.difference_update(removed)
            members.update(added)
            changed = sorted([*added, *removed], key=FIELDS)  # put in an order no hash decides
        tested: dict[str, None] = {}
        for spring in changed:
            tested.update(dict.fromkeys(spring.ends))
        for name, point in fixed.items():
            if last.fixed.get(name) != (point.x, point.y):
                for spring in self._index.around([name]):
                    tested.update(dict.fromkeys(spring.ends))
        return _Disturbance([*new, *last.moving], list(tested), members)

    def as_last_settled(self) -> list[str] | None:
        """If nothing has changed since the last settle, the places it left moving (|v| >= L_v); else None.

        A saved model keeps this, so a loaded one settles exactly as the original would
        (:meth:`resume_settled`); without it the first settle after loading moves every place."""
        last = self._last_settle
        if last is None:
            return None
        springs = self.resolved_springs()
        same = (set(springs) == last.members and len(springs) - len(last.members) == last.duplicates
                and {n: (f.x, f.y) for n, f in self.fixed.items()} == last.fixed
                and set(self.places()) <= set(self.positions))
        return list(last.moving) if same else None

    def resume_settled(self, moving: Iterable[str]) -> None:
        """Take the model as its last settle left it, with ``moving`` still moving (see :meth:`as_last_settled`)."""
        springs = self.resolved_springs()
        self._index = SpringIndex(springs)
        self._last_settle = _LastSettle.of(springs, self.fixed, [p for p in moving if p in self.positions])

    def settle(self, *, max_steps: int | None = None, max_s: float | None = None) -> SettleReport:
        """Place new masses (Algorithm 2), then integrate until settled (Algorithm 1) or a cap is hit.

        ``max_steps``: steps for this call (default ``params.dynamics.max_iterations``); ``max_s``: seconds of
        wall time for this call (default none; the clock is read every 16 steps, so a few may run over). A
        capped settle keeps where the masses got to, its report says which cap stopped it, and the next
        settle carries on from there."""
        max_steps, max_s = settle_caps(max_steps, max_s)
        began = time.perf_counter()
        springs = self._cached("resolved", self._resolved_springs, self.exploration_factor)  # cached list: read only
        places = self.places()
        new = [p for p in places if p not in self.positions]
        disturbed = self._disturbed(springs, new, self.fixed)
        placed: dict[str, np.ndarray] = {}
        if new:  # Algorithm 2 needs only the springs touching a new mass
            known = {**{n: f.xy for n, f in self.fixed.items()}, **self.positions}
            origin = np.array(self.start[:2])
            new_set = set(new)
            near = [s for s in springs if not new_set.isdisjoint(s.ends)]
            placed = place_new_masses(new, known, near, origin=origin, heading=self.start[2],
                                      min_separation=self.params.dynamics.min_separation)
        for name, xy in placed.items():
            self.positions[name] = xy
            self.velocities[name] = np.zeros(2)
        parents = set(self.hierarchy.parent.values())
        expand = set(places) if self.params.dynamics.expansion_on == "all" else \
            {p for p in places if p not in parents}
        fixed = {n: f.xy for n, f in self.fixed.items()}
        try:
            self._field.prepare(self._cached("clause springs", self._springs_of_clauses), springs, self._index,
                                self.params.dynamics.angle_length, self._resolver.values_of(springs))
            result = run_dynamics(self.positions, self.velocities, fixed, self._index, active=disturbed.active,
                                  tested=[p for p in disturbed.tested if p in self.positions], field=self._field,
                                  expand=expand, centre=self.explored_centre, params=self.params.dynamics,
                                  max_steps=max_steps, deadline=None if max_s is None else began + max_s)
        except BaseException:
            self._last_settle = None  # the spring index already took this settle's changes: start afresh
            raise
        bad = [n for n, xy in result.positions.items() if not np.all(np.abs(xy) <= errors.COORDINATE_LIMIT_M)]
        if bad:  # never expected with checked inputs: refuse rather than hand out NaN
            for name in placed:
                self.positions.pop(name, None)
                self.velocities.pop(name, None)
            self._last_settle = None  # the spring index already took this settle's changes: start afresh
            raise ModelError(f"settle diverged: {bad[0]!r} left the +-{errors.COORDINATE_LIMIT_M:g} m range; "
                             "the model is unchanged")
        self.positions.update(result.positions)
        self.velocities.update(result.velocities)
        limit = self.params.dynamics.settle_velocity
        self._last_settle = _LastSettle.of(springs, self.fixed, [n for n, v in result.velocities.items()
                                                                 if float(np.hypot(*v)) >= limit], disturbed.members)
        return SettleReport(result.settled, result.iterations, time.perf_counter() - began, tuple(new),
                            result.stopped_by, len(result.positions))


def settle_caps(max_steps: object, max_s: object, *, names: tuple[str, str] = ("settle max_steps", "settle max_s"),
                error: type[errors.AbstractMapError] = ModelError) -> tuple[int | None, float | None]:
    """The per-call caps of :meth:`AbstractMap.settle`, checked: ``max_steps`` an integer in [1, 1e9),
    ``max_s`` seconds in [1e-6, 1e9]; either may be None (no cap of that kind). ``names`` name them in errors."""
    steps = None if max_steps is None else errors.integer(names[0], max_steps, low=1, high=10**9, error=error)
    seconds = None if max_s is None else errors.number(names[1], max_s, low=1e-6, high=1e9, error=error)
    return steps, seconds


EXPLORATION_LAWS = {
    "multiplicative": lambda factor, step: factor * (1.0 + step),
    "additive": lambda factor, step: factor + step,
}


def imagined_positions(model: AbstractMap) -> Mapping[str, tuple[float, float]]:
    """Positions of every place as plain floats, for JSON."""
    return {name: (float(xy[0]), float(xy[1])) for name, xy in model.positions.items()}
