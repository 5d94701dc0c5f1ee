"""Clauses to springs, through the preposition table.

A :class:`Spring` is a value: its kind, the masses it joins (place names or
anchor names), its natural value (unit lengths for distance springs, radians
for angle springs) and stiffness. Natural lengths in metres come later, from
the scale factors (``scales.py``), so that learning a scale never changes the
set of springs.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from .clauses import Clause, Locational, Relational, is_anchor
from .params import STIFFNESS
from .prepositions import LOCATIONAL, TABLE, Rule
from .values import RememberedHash

log = logging.getLogger(__name__)

SPRING_KINDS = ("distance", "global_angle", "relative_angle")
SCALE_KINDS = ("place", "sign", "label", "start")


@dataclass(frozen=True)
class Spring(RememberedHash):
    """A spring between masses.

    distance: ``ends = (a, b)``, ``value`` in unit lengths, ``scale`` picks the scale table.
    global_angle: ``ends = (reference, figure)``, ``value`` = direction (rad, world) of figure from reference.
    relative_angle: ``ends = (a, vertex, b)``, ``value`` = angle (rad) at vertex from a to b.
    """

    kind: str
    ends: tuple[str, ...]
    value: float
    stiffness: float  # N/m (distance) or N/rad (angles)
    scale: str = "place"  # distance springs only: "place", "sign", "label" or "start"

    __hash__ = RememberedHash.__hash__  # in the class body, or the dataclass would write its own


AnchorKind = Callable[[str], str]
"""Maps an anchor name to its kind: "label", "sign" or "start"."""


def _scale_for(ends: tuple[str, str], anchor_kind: AnchorKind) -> str:
    anchors = [e for e in ends if is_anchor(e)]
    if not anchors:
        return "place"
    if len(anchors) == 2:
        raise ValueError(f"distance spring between two fixed points {ends}: nothing can move")
    return anchor_kind(anchors[0])


def _bind(role: str, clause: Relational) -> list[str]:
    if role == "figure":
        return [clause.figure]
    if role == "referent":
        return list(clause.referents)
    if role.startswith("referent"):
        index = int(role[len("referent"):])
        return [clause.referents[index]] if index < len(clause.referents) else []
    if role == "context":
        return [clause.context] if clause.context else []
    raise ValueError(f"unknown role {role!r} in the preposition table")


def _relational_springs(clause: Relational, anchor_kind: AnchorKind, flags: dict[str, bool]) -> list[Spring]:
    row = TABLE.get(clause.preposition)
    if row is None:
        raise ValueError(f"clause {clause}: preposition {clause.preposition!r} has no row in the table")
    springs: list[Spring] = []
    for rule in row.rules:
        if rule.optional and not flags.get(rule.optional, False):
            continue
        bound = [_bind(role, clause) for role in rule.ends]
        if any(not b for b in bound):
            log.warning("clause %s: no %s, so its %s spring is left out", clause,
                        " / ".join(r for r, b in zip(rule.ends, bound) if not b), rule.kind)
            continue
        # "referent" expands to one spring per referent; other roles bind one mass each.
        for combo in _expand(bound):
            if len(set(combo)) < len(combo):
                raise ValueError(f"clause {clause}: a {rule.kind} spring would join {combo[0]!r} to itself")
            springs.append(_spring(rule, tuple(combo), anchor_kind, base_angle=0.0))
    return springs


def _expand(bound: list[list[str]]) -> list[list[str]]:
    combos: list[list[str]] = [[]]
    for options in bound:
        combos = [c + [o] for c in combos for o in options]
    return combos


def _spring(rule: Rule, ends: tuple[str, ...], anchor_kind: AnchorKind, *, base_angle: float) -> Spring:
    stiffness = STIFFNESS[rule.stiffness]
    if rule.kind == "distance":
        return Spring("distance", ends, rule.value, stiffness, _scale_for((ends[0], ends[1]), anchor_kind))
    if rule.kind == "global_angle":
        return Spring("global_angle", ends, math.remainder(base_angle + rule.value, math.tau), stiffness)
    if rule.kind == "relative_angle":
        return Spring("relative_angle", ends, rule.value, stiffness)
    raise ValueError(f"unknown spring kind {rule.kind!r}; known: {SPRING_KINDS}")


def _locational_springs(clause: Locational, anchor_kind: AnchorKind) -> list[Spring]:
    rules = LOCATIONAL.get(clause.kind)
    if rules is None:
        raise ValueError(f"clause {clause}: locational kind {clause.kind!r} is not one of {sorted(LOCATIONAL)}")
    roles = {"toponym": clause.toponym, "anchor": clause.anchor}
    return [_spring(rule, tuple(roles[r] for r in rule.ends), anchor_kind, base_angle=clause.direction)
            for rule in rules]


def clause_springs(clause: Clause, anchor_kind: AnchorKind, flags: dict[str, bool] | None = None) -> list[Spring]:
    """The springs one clause asks for."""
    if isinstance(clause, Relational):
        return _relational_springs(clause, anchor_kind, flags or {})
    return _locational_springs(clause, anchor_kind)


def add_clause_springs(unique: dict[Spring, None], clauses: Iterable[Clause], anchor_kind: AnchorKind,
                       flags: dict[str, bool] | None = None, *, memo: dict[Clause, list[Spring]] | None = None) -> None:
    """Add the springs of ``clauses`` to ``unique``, each spring once, in first-seen order. ``memo``, if given,
    keeps each clause's springs from one call to the next (valid while ``anchor_kind`` and ``flags`` stay the
    same)."""
    for clause in clauses:
        made = None if memo is None else memo.get(clause)
        if made is None:
            made = clause_springs(clause, anchor_kind, flags)
            if memo is not None:
                memo[clause] = made
        unique.update(dict.fromkeys(made))


def springs_from_clauses(clauses: Iterable[Clause], anchor_kind: AnchorKind,
                         flags: dict[str, bool] | None = None) -> list[Spring]:
    """All springs of the clauses, each spring once, in first-seen order."""
    unique: dict[Spring, None] = {}
    add_clause_springs(unique, clauses, anchor_kind, flags)
    return list(unique)
