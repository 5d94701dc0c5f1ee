"""Check a world against its own floor plan: tags on walls and readable, places reachable, signs true.

``check_world(world)`` returns a :class:`CheckReport`, a list of findings,
each with a kind, what it concerns (a tag, a goal, a place) and a one-line
message. It checks, with the rules of ``truth``:

- ``wall``: every tag has a wall right behind it (within 0.2 m behind, or the
  tag is drawn inside a wall whose free face is within 0.2 m in front: the
  scene's rule for hanging tags);
- ``unreadable``: every tag can be read (4 m, in its 90-degree cone, line of
  sight) from free space the robot, inflated by 0.38 m, can reach from the start;
- ``grammar``: every tag's text parses; ``name``: every label names a place of
  the hierarchy;
- ``room``/``goal``: every room (a leaf of the hierarchy) and every goal has a
  label readable from reachable space; each goal's oracle is computed;
- ``arrow``: every arrow lies within 45 degrees of its route's first leg (of
  its place's bearing in a world whose ``generator.arrows`` is ``bearing``:
  ``truth.ARROW_READINGS``);
- ``phrase``: every phrase is true by its preposition's test;
- ``oracle``: a stored ``oracle_m`` agrees with the computed one (0.05 m + 1 %).

Arrows a generated world declares misleading (``generator.misleading`` in
world.json) are reported as ``declared`` and do not fail the check.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from abstract_map.clauses import Locational, Relational
from abstract_map.grammar import CueError
from abstract_map.hierarchy import Hierarchy, HierarchyError
from sim.world.data import Tag, World
from sim.world.oracle import oracle_paths
from sim.world.truth import (
    ARROW_READINGS,
    DEFAULT_ARROWS,
    ArrowReading,
    Facts,
    RouteField,
    Routes,
    TruthParams,
    hang,
    phrase_verdict,
    place_positions,
    place_tags,
)

ORACLE_TOLERANCE = (0.05, 0.01)  # m and fraction: a stored oracle length this close to the computed one is current


@dataclass(frozen=True)
class Finding:
    kind: str  # wall, unreadable, grammar, name, room, goal, arrow, phrase, oracle, start, hierarchy
    subject: str  # "tag 12", "goal Lion", "place Toilets"
    message: str
    declared: bool = False  # an error the world declares on purpose (misleading signage)


@dataclass
class CheckReport:
    world: str
    findings: list[Finding] = field(default_factory=list)
    oracle_m: dict[str, float] = field(default_factory=dict)  # m, computed per goal
    checked: dict[str, int] = field(default_factory=dict)  # what was checked: tags, arrows, phrases, places

    @property
    def failures(self) -> list[Finding]:
        return [f for f in self.findings if not f.declared]

    @property
    def ok(self) -> bool:
        return not self.failures

    def add(self, kind: str, subject: str, message: str, declared: bool = False) -> None:
        self.findings.append(Finding(kind, subject, message, declared))

    def table(self) -> str:
        """A markdown table of the findings and a summary line."""
        counts = ", ".join(f"{v} {k}" for k, v in self.checked.items())
        lines = [f"world {self.world}: checked {counts}"]
        if self.findings:
            lines += ["", "| kind | concerns | finding |", "| --- | --- | --- |"]
            for f in self.findings:
                kind = f"{f.kind} (declared)" if f.declared else f.kind
                lines.append(f"| {kind} | {f.subject} | {f.message.replace('|', '/')} |")
            lines.append("")
        oracle = ", ".join(f"{g} {m:.2f} m" for g, m in sorted(self.oracle_m.items()))
        lines.append(f"oracle: {oracle or '-'}")
        n = len(self.failures)
        lines.append("OK: nothing fails" if n == 0 else f"FAIL: {n} finding(s) fail")
        return "\n".join(lines)


def check_world(world: World, *, hierarchy: Hierarchy | None = None, params: TruthParams | None = None) -> CheckReport:
    """Check ``world`` (module docstring)."""
    params = params or TruthParams()
    report = CheckReport(world.name)
    if hierarchy is None:
        try:
            hierarchy = Hierarchy.from_xml(world.hierarchy_path)
        except (HierarchyError, OSError) as exc:
            report.add("hierarchy", str(world.hierarchy_path), str(exc))
            hierarchy = Hierarchy()
    routes = Routes(world.floorplan, params)
    start_field = routes.field_from(np.array(world.start[:2]))
    if start_field is None:
        report.add("start", "start", f"the start {world.start[:2]} is within {params.robot_radius_m} m of a wall")

    clauses: dict[int, list] = {}
    hung: dict[int, Tag] = {}
    for tag in sorted(world.tags.values(), key=lambda t: t.id):
        subject = f"tag {tag.id}"
        hung[tag.id], problem = hang(world.floorplan, tag)
        if problem:
            report.add("wall", subject, problem)
        if start_field is not None and not start_field.reaches(hung[tag.id]):
            report.add("unreadable", subject, f"{tag.kind} {_short(tag.text)}: no reachable free cell reads it "
                       f"({params.read_range_m} m, {params.cone_half_angle_deg:.0f} deg cone, line of sight)")
        if tag.kind == "empty":
            continue
        try:
            clauses[tag.id] = tag.clauses()
        except CueError as exc:
            report.add("grammar", subject, str(exc))
            continue
        if tag.kind == "label" and tag.text not in hierarchy.places:
            report.add("name", subject, f"label {tag.text!r} names no place of the hierarchy")
    world = replace(world, tags=hung)  # from here on, tags are where the scene hangs them

    reached_label = {t.text for t in world.tags.values() if t.kind == "label"
                     and start_field is not None and start_field.reaches(t)}
    leaves = hierarchy.leaves()
    for place in leaves:
        if place in world.goals:
            continue
        if place not in reached_label:
            why = "no label" if not any(t.kind == "label" and t.text == place for t in world.tags.values()) \
                else "no label of it can be read from reachable space"
            report.add("room", f"place {place}", f"unreachable: {why}")
    goals = sorted(world.goals)
    reachable_goals = [g for g in goals if g in reached_label]
    for g in goals:
        if g not in reachable_goals:
            report.add("goal", f"goal {g}", "unreachable: no label of it can be read from reachable space")
    if start_field is not None and reachable_goals:
        computed = oracle_paths(world, reachable_goals, params=params.oracle)
        report.oracle_m = {g: round(p.length_m, 3) for g, p in computed.items()}
    for g, stored in sorted((world.oracle_m or {}).items()):
        now = report.oracle_m.get(g)
        if now is not None and abs(now - stored) > ORACLE_TOLERANCE[0] + ORACLE_TOLERANCE[1] * now:
            report.add("oracle", f"goal {g}", f"stored oracle {stored:.2f} m, computed {now:.2f} m "
                       "(rewrite it with: abstract-map world check --write-oracle)")

    facts = Facts(place_positions(hierarchy, world.tags, params.behind_m), hierarchy, params)
    for tag in world.tags.values():
        if tag.kind == "sign":
            facts.positions[f"#{tag.id}"] = np.array([tag.x, tag.y])
            facts.facing[f"#{tag.id}"] = tag.theta
    declared = {(int(m["tag"]), str(m["name"])) for m in (world.generator or {}).get("misleading", [])}
    arrows = str((world.generator or {}).get("arrows", DEFAULT_ARROWS))
    if arrows not in ARROW_READINGS:
        report.add("arrow", "world", f"generator.arrows {arrows!r}: expected one of {', '.join(ARROW_READINGS)}; "
                   f"arrows checked as {DEFAULT_ARROWS!r}")
        arrows = DEFAULT_ARROWS
    n_arrows = n_phrases = 0
    for tag_id, found in sorted(clauses.items()):
        tag = world.tags[tag_id]
        if tag.kind != "sign":
            continue
        field_: RouteField | None = None
        pose = routes.reading_pose(tag)
        for clause in found:
            if isinstance(clause, Locational) and clause.kind == "arrow":
                n_arrows += 1
                if field_ is None and pose is not None:
                    field_ = routes.field_from(pose)
                problem = _arrow_problem(clause, tag, field_, routes, hierarchy, world, facts,
                                         ARROW_READINGS[arrows])
                if problem:
                    report.add("arrow", f"tag {tag_id}", problem, declared=(tag_id, clause.toponym) in declared)
            elif isinstance(clause, Relational):
                n_phrases += 1
                problem = phrase_verdict(facts, clause.preposition, clause.figure, tuple(clause.referents),
                                         clause.context)
                if problem:
                    report.add("phrase", f"tag {tag_id}", f"{_phrase(clause, tag_id)}: {problem}")
    report.checked = {"tags": len(world.tags), "arrows": n_arrows, "phrases": n_phrases, "places": len(leaves),
                      "goals": len(goals)}
    return report


def _short(text: str, n: int = 40) -> str:
    one = text.replace("\n", " / ")
    return repr(one if len(one) <= n else one[: n - 3] + "...")


def _phrase(clause: Relational, tag_id: int) -> str:
    refs = " and ".join("here" if r == f"#{tag_id}" else r for r in clause.referents)
    return f"'{clause.figure} is {clause.preposition} {refs}'"


def _arrow_problem(clause: Locational, tag: Tag, field_: RouteField | None, routes: Routes, hierarchy: Hierarchy,
                   world: World, facts: Facts, reading: ArrowReading) -> str | None:
    name = clause.toponym
    arrow = _arrow_word(tag.theta, clause.direction)
    head = f"${arrow}$ {name}"
    targets = place_tags(name, hierarchy, world.tags)
    if not targets:
        return f"{head}: no label of {name!r} (or of a place in it) to route to"
    if field_ is None:
        return f"{head}: no free cell in front of the sign to read it from"
    path = field_.route_to(targets)
    if path is None:
        return f"{head}: {name!r} cannot be reached from in front of the sign"
    leg = reading.direction(path, facts.positions.get(name), routes.params)
    if leg is None:
        return f"{head}: {reading.describes} is not defined"
    error = abs(math.degrees(math.remainder(leg - clause.direction, math.tau)))
    if error <= routes.params.tolerance_deg:
        return None
    return (f"{head}: the arrow points {math.degrees(clause.direction):.0f} deg, {reading.describes} "
            f"{math.degrees(leg):.0f} deg ({error:.0f} deg off; route {_length(path):.1f} m)")


def _length(path: np.ndarray) -> float:
    return float(np.hypot(*np.diff(path, axis=0).T).sum()) if len(path) > 1 else 0.0


def _arrow_word(theta: float, direction: float) -> str:
    from abstract_map.prepositions import ARROWS

    return min(ARROWS, key=lambda a: abs(math.remainder(theta + ARROWS[a] - direction, math.tau)))


def write_oracle(world_dir: Path, oracle_m: dict[str, float]) -> None:
    """Store ``oracle_m`` in the folder's world.json (other keys and their order kept)."""
    path = Path(world_dir) / "world.json"
    meta = json.loads(path.read_text())
    meta["oracle_m"] = {g: oracle_m[g] for g in sorted(oracle_m)}
    path.write_text(json.dumps(meta, indent=2) + "\n")
