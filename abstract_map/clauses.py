"""Clauses of the robotics-oriented grammar (Section III-A of the paper).

Toponyms are place names. Fixed points in the world (a sign or label tag, the
start pose) are *anchors*, named ``#<tag id>`` or ``#start``; a place name can
never start with ``#``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

ANCHOR_PREFIX = "#"
START_ANCHOR = "#start"
NAMED_BY = ("phrase", "arrow", "hierarchy")  # how cues name a place, the surest way first (:func:`named_by`)


def tag_anchor(tag_id: int) -> str:
    """The anchor name of a tag."""
    return f"{ANCHOR_PREFIX}{tag_id}"


def is_anchor(name: str) -> bool:
    return name.startswith(ANCHOR_PREFIX)


@dataclass(frozen=True)
class Relational:
    """``rel(preposition, figure, {referents}, context)``: the figure relative to the referents."""

    preposition: str
    figure: str
    referents: tuple[str, ...]
    context: str | None = None  # a toponym or an anchor; None when the cue gives none

    def to_dict(self) -> dict[str, object]:
        return {"type": "relational", "preposition": self.preposition, "figure": self.figure,
                "referents": list(self.referents), "context": self.context}


@dataclass(frozen=True)
class Locational:
    """``loc(toponym, W, x, y, r, theta)``: a place located from a fixed point in the world.

    ``kind`` is "label" (the place lies behind the tag: ``direction`` is the tag's
    normal plus pi), "arrow" (the place lies in ``direction`` from the sign) or
    "here" (a place a sign calls "here" lies behind it, distance unsaid).
    """

    kind: str
    toponym: str
    anchor: str  # name of the fixed point, e.g. "#3"
    direction: float  # rad, world frame, from the anchor to the place

    def to_dict(self) -> dict[str, object]:
        return {"type": "locational", "kind": self.kind, "toponym": self.toponym,
                "anchor": self.anchor, "direction": self.direction}


Clause = Relational | Locational


def clause_from_dict(data: dict[str, object]) -> Clause:
    """Inverse of ``to_dict`` for either clause type."""
    if data.get("type") == "relational":
        context = data["context"]
        return Relational(str(data["preposition"]), str(data["figure"]),
                          tuple(str(r) for r in data["referents"]),  # type: ignore[attr-defined]
                          None if context is None else str(context))
    if data.get("type") == "locational":
        return Locational(str(data["kind"]), str(data["toponym"]), str(data["anchor"]),
                          float(data["direction"]))  # type: ignore[arg-type]
    raise ValueError(f"clause {data!r}: expected 'type' to be 'relational' or 'locational'")


def clause_names(clause: Clause) -> list[str]:
    """Every name a clause mentions: places and anchors (a relational clause's figure, referents and context; a
    locational clause's toponym and anchor)."""
    if isinstance(clause, Relational):
        return [clause.figure, *clause.referents, *([clause.context] if clause.context else [])]
    return [clause.toponym, clause.anchor]


def named_by(clauses: Iterable[Clause], place: str, canonical: Callable[[str], str] = str) -> str:
    """How ``clauses`` name ``place``, the surest way (:data:`NAMED_BY`): ``"phrase"`` when a relational
    clause has it as its figure or a referent, else ``"arrow"`` when an arrow points to it, else
    ``"hierarchy"`` (no cue names it: only the hierarchy places it). Names are compared after ``canonical``."""
    arrow = False
    for c in clauses:
        if isinstance(c, Relational) and place in {canonical(n) for n in (c.figure, *c.referents)}:
            return "phrase"
        arrow = arrow or (isinstance(c, Locational) and c.kind == "arrow" and canonical(c.toponym) == place)
    return "arrow" if arrow else "hierarchy"
