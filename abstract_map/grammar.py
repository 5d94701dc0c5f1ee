"""Parse cue text into clauses.

A cue is either a label (its whole text names the place behind the tag) or a
sign of one or more lines. Lines are separated by newlines or by the two
characters backslash-n (as in the QUT cue mapping). A sign line is one of:

- an arrow: ``$LEFT$ A, B and C`` (with or without a space after the arrow);
- a phrase: ``[from CONTEXT,] FIGURES is|are PREPOSITION REFERENTS[, from CONTEXT]``,
  where FIGURES and REFERENTS are lists joined by commas and "and", and the
  referent "here" means the sign itself; a place "near here" also gets a
  "here" clause: like a label's place, it lies behind the sign's face.

Leading articles ("the", and a lower-case "a"/"an") are not part of a name.
Anything that cannot be parsed raises :class:`CueError` naming the line.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from .clauses import Clause, Locational, Relational
from .errors import CueError, place_name, show
from .prepositions import ARROWS, HERE_WORDS, TABLE, Preposition

__all__ = ["Anchor", "CueError", "parse_cue", "parse_line", "split_lines"]

MAX_CUE_CHARS = 100_000
"""Characters in one cue's text: far more than any sign (the zoo's longest has 120)."""


@dataclass(frozen=True)
class Anchor:
    """Where a cue was read: a fixed point with the direction its face points (rad, world)."""

    name: str
    x: float  # m
    y: float  # m
    theta: float  # rad

    def __post_init__(self) -> None:
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in (self.x, self.y, self.theta)):
            raise CueError(f"anchor {self.name!r}: pose ({self.x}, {self.y}, {self.theta}) must be finite")


_ARROW = re.compile(r"^\$(?P<arrow>\w+)\$\s*(?P<names>.*)$")
_LEADING_CONTEXT = re.compile(r"^from\s+(?P<context>[^,]+),\s*(?P<rest>.+)$", re.IGNORECASE)
_TRAILING_CONTEXT = re.compile(r"^(?P<rest>.+?),\s*from\s+(?P<context>[^,]+)$", re.IGNORECASE)
_COPULA = re.compile(r"^(?P<figures>.+?)\s+(?:is|are)\s+(?P<tail>.+)$", re.IGNORECASE)
_PREPOSITION = re.compile(
    r"^(?P<prep>" + "|".join(re.escape(w) for w in sorted(TABLE, key=len, reverse=True)) + r")\s+(?P<refs>.+)$",
    re.IGNORECASE,
)
_LIST_SPLIT = re.compile(r"\s*,\s*(?:and\s+)?|\s+and\s+")
_ARTICLE = re.compile(r"^(?:(?i:the)|a|an)\s+")


def split_lines(text: str) -> list[str]:
    """Lines of a cue: split on newlines and on the two characters backslash-n."""
    return [line.strip() for line in text.replace("\\n", "\n").split("\n") if line.strip()]


def clean_name(name: str, *, where: str) -> str:
    """A place name without its leading article or trailing full stop."""
    cleaned = _ARTICLE.sub("", name.strip().rstrip(".").strip()).strip()
    return place_name(where, cleaned, error=CueError)


def split_names(text: str, *, where: str) -> list[str]:
    """``"A, B and C"`` -> ``["A", "B", "C"]``."""
    return [clean_name(part, where=where) for part in _LIST_SPLIT.split(text.strip()) if part.strip()]


def parse_arrow(line: str, anchor: Anchor | None, *, where: str) -> list[Clause]:
    """``$LEFT$ A, B`` -> one arrow clause per place, direction from the sign's pose."""
    match = _ARROW.match(line)
    if match is None:
        raise CueError(f"{where}: not an arrow line")
    arrow = match["arrow"].upper()
    if arrow not in ARROWS:
        raise CueError(f"{where}: unknown arrow ${match['arrow']}$; known arrows: {sorted(ARROWS)}")
    if anchor is None:
        raise CueError(f"{where}: an arrow needs the pose of the sign it is on")
    names = split_names(match["names"], where=where)
    if not names:
        raise CueError(f"{where}: arrow ${arrow}$ points to no place")
    direction = math.remainder(anchor.theta + ARROWS[arrow], math.tau)
    return [Locational("arrow", name, anchor.name, direction) for name in names]


def _resolve(name: str, anchor: Anchor | None, *, where: str) -> str:
    if name.lower() in HERE_WORDS:
        if anchor is None:
            raise CueError(f"{where}: 'here' needs the pose of the sign it is on")
        return anchor.name
    return clean_name(name, where=where)


def parse_phrase(line: str, anchor: Anchor | None, *, where: str) -> list[Clause]:
    """``[from C,] X[, Y and Z] is|are PREP A[, B]`` -> one relational clause per figure."""
    body, context = line.rstrip("."), None
    for pattern in (_LEADING_CONTEXT, _TRAILING_CONTEXT):
        match = pattern.match(body)
        if match:
            body, context = match["rest"], _resolve(match["context"], anchor, where=where)
            break
    copula = _COPULA.match(body)
    if copula is None:
        raise CueError(f"{where}: expected 'FIGURE is PREPOSITION REFERENT' or an arrow like '$LEFT$ Place'")
    prep_match = _PREPOSITION.match(copula["tail"])
    if prep_match is None:
        word = copula["tail"].split()[0]
        raise CueError(f"{where}: unknown preposition {show(word)}; known prepositions: {sorted(TABLE)}")
    preposition = prep_match["prep"].lower()
    row = TABLE[preposition]
    figures = [_resolve(f, anchor, where=where) for f in _LIST_SPLIT.split(copula["figures"]) if f.strip()]
    referents = tuple(_resolve(r, anchor, where=where) for r in _LIST_SPLIT.split(prep_match["refs"]) if r.strip())
    low, high = row.referents
    if not low <= len(referents) <= high:
        raise CueError(f"{where}: {preposition!r} takes {low} to {high} referents, got {len(referents)}")
    if context is None and anchor is not None:
        context = anchor.name
    _check_roles(figures, referents, context, row, preposition, where=where)
    clauses: list[Clause] = [Relational(preposition, figure, referents, context) for figure in figures]
    if anchor is not None and anchor.name in referents and not row.hierarchy:
        behind = math.remainder(anchor.theta + math.pi, math.tau)
        clauses += [Locational("here", figure, anchor.name, behind) for figure in figures]
    return clauses


def _check_roles(figures: list[str], referents: tuple[str, ...], context: str | None, row: Preposition,
                 preposition: str, *, where: str) -> None:
    """Refuse a phrase whose places coincide where its springs need distinct masses."""
    refs = [r.casefold() for r in referents]
    if len(set(refs)) < len(refs):
        raise CueError(f"{where}: a referent of {preposition!r} is named twice")
    for figure in figures:
        if figure.casefold() in refs:
            raise CueError(f"{where}: {figure!r} cannot be {preposition} itself")
    uses_context = any("context" in rule.ends for rule in row.rules)
    if uses_context and context is not None and context.casefold() in refs + [f.casefold() for f in figures]:
        raise CueError(f"{where}: {preposition!r} is judged from where the reader stands, which is 'here' "
                       f"(the sign) unless the line says otherwise; write 'from PLACE, X is {preposition} here'")


def parse_line(line: str, anchor: Anchor | None, *, where: str = "cue") -> list[Clause]:
    """One sign line (arrow or phrase) to clauses."""
    line = line.strip()
    if _ARROW.match(line):
        return parse_arrow(line, anchor, where=where)
    return parse_phrase(line, anchor, where=where)


def looks_like_sign(text: str) -> bool:
    """True if the text has several lines, an arrow or a phrase; False for a bare label."""
    lines = split_lines(text)
    return len(lines) != 1 or bool(_ARROW.match(lines[0]) or _COPULA.match(lines[0]))


def parse_cue(text: str, anchor: Anchor | None = None, *, kind: str | None = None) -> list[Clause]:
    """Clauses of a cue. ``kind`` is "label", "sign" or None (inferred from the text)."""
    where_tag = f"cue at {anchor.name}" if anchor else "cue"
    if not isinstance(text, str):
        raise CueError(f"{where_tag}: text must be a string, got {show(text)}")
    if not text.strip():
        raise CueError(f"{where_tag}: empty text")
    if len(text) > MAX_CUE_CHARS:
        raise CueError(f"{where_tag}: {len(text)} characters; a cue has at most {MAX_CUE_CHARS}")
    if kind is None:
        kind = "sign" if looks_like_sign(text) else "label"
    if kind == "label":
        if anchor is None:
            raise CueError(f"{where_tag}: a label {show(text)} needs the pose of its tag")
        name = clean_name(text, where=f"{where_tag} label {show(text)}")
        return [Locational("label", name, anchor.name, math.remainder(anchor.theta + math.pi, math.tau))]
    if kind != "sign":
        raise CueError(f"{where_tag}: kind {show(kind)} is not 'label' or 'sign'")
    clauses: list[Clause] = []
    for number, line in enumerate(split_lines(text), start=1):
        clauses.extend(parse_line(line, anchor, where=f"{where_tag} line {number} {show(line)}"))
    return clauses
