"""The preposition table: how each spatial preposition becomes springs.

A new preposition is one row here, not new code. Each rule names its ends by
role: ``figure``, ``referent`` (one spring per referent), ``referent0`` /
``referent1`` (a specific referent), ``context`` and ``anchor`` (the fixed point
of a locational clause). Values are unit natural lengths for distance springs
and radians for angle springs; stiffness is a name from ``params.STIFFNESS``.

Angle conventions (method.md): a global angle spring holds the direction of its
second end as seen from its first; a relative angle spring ``(a, v, b)`` holds
the angle at ``v`` from ``a`` to ``b``, counter-clockwise. "Right of" is the
reader's right when standing at the context facing the referent (+pi/2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

PI = math.pi


@dataclass(frozen=True)
class Rule:
    """One spring produced by a preposition."""

    kind: str  # "distance" | "global_angle" | "relative_angle"
    ends: tuple[str, ...]  # roles, 2 for distance/global angle, 3 for relative angle
    value: float  # unit natural length, or rad (global angles: offset added to the clause's direction)
    stiffness: str  # name in params.STIFFNESS
    optional: str | None = None  # a params flag that switches this rule on


@dataclass(frozen=True)
class Preposition:
    """A row of the table: the words that name it, its springs and referent count."""

    words: tuple[str, ...]
    rules: tuple[Rule, ...]
    referents: tuple[int, int] = (1, 1_000)  # allowed number of referents (min, max)
    hierarchy: bool = False  # also a parent-child edge (figure in referent)


def _dist(units: float, stiffness: str, a: str = "figure", b: str = "referent") -> Rule:
    return Rule("distance", (a, b), units, stiffness)


PREPOSITIONS: tuple[Preposition, ...] = (
    Preposition(("past", "after", "beyond"),
                (Rule("relative_angle", ("context", "referent", "figure"), PI, "L"), _dist(1.0, "S"))),
    Preposition(("before", "towards", "toward"),
                (Rule("relative_angle", ("context", "figure", "referent"), PI, "L"), _dist(1.0, "S"))),
    Preposition(("left of", "to the left of"),
                (Rule("relative_angle", ("context", "referent", "figure"), -PI / 2, "L"), _dist(1.0, "S"))),
    Preposition(("right of", "to the right of"),
                (Rule("relative_angle", ("context", "referent", "figure"), PI / 2, "L"), _dist(1.0, "S"))),
    Preposition(("beside", "by", "near", "with", "next to"), (_dist(0.5, "L"),)),
    Preposition(("between",),
                (_dist(1.0, "L"),
                 Rule("relative_angle", ("referent0", "figure", "referent1"), PI, "M", optional="between_angle")),
                referents=(2, 2)),
    Preposition(("in", "inside", "within"), (_dist(1.0, "XS"),), hierarchy=True),
)

LOCATIONAL: dict[str, tuple[Rule, ...]] = {
    # The place lies behind its label, at the label scale; observations are stiff.
    "label": (Rule("distance", ("toponym", "anchor"), 1.0, "XL"),
              Rule("global_angle", ("anchor", "toponym"), 0.0, "XL")),
    # An arrow on a sign: the place lies that way, at the sign scale.
    "arrow": (Rule("distance", ("toponym", "anchor"), 1.0, "S"),
              Rule("global_angle", ("anchor", "toponym"), 0.0, "M")),
    # "X is near here": like a label, the sign marks a place behind its face; the distance comes
    # from the phrase's own preposition (our addition: the paper gives "here" no direction).
    "here": (Rule("global_angle", ("anchor", "toponym"), 0.0, "M"),),
}

ARROWS: dict[str, float] = {
    # Offset (rad) from the sign's facing direction to the pointed direction, for a
    # reader standing in front of the sign and facing it.
    "LEFT": -PI / 2,
    "RIGHT": PI / 2,
    "UP": PI,  # ahead of the reader, through the sign
    "DOWN": 0.0,  # behind the reader
}

HERE_WORDS: tuple[str, ...] = ("here",)
"""Referents that mean the sign itself."""


def preposition_table() -> dict[str, Preposition]:
    """Every preposition word to its row."""
    table: dict[str, Preposition] = {}
    for row in PREPOSITIONS:
        for word in row.words:
            if word in table:
                raise ValueError(f"preposition {word!r} appears in two rows of the table")
            table[word] = row
    return table


TABLE: dict[str, Preposition] = preposition_table()
