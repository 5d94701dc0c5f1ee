"""When a sign tells the truth: one geometric test per preposition, and the arrow test.

Shared by the generator (it writes only what these call true) and the world
check (it reports what they call false). Positions come from what a world
folder holds:

- a place with a label lies ``behind_m`` behind the label's face (the mean
  over its labels, when it has several): a label is the direct evidence of
  where a place is (rooms; areas labelled at their entrance, as in the zoo);
- a place with no label lies at the mean of its children's positions (areas,
  wings, the building); one with neither has no position;
- a sign's context ("here", or no ``from ...``) is the sign's tag position.

Tests (``tolerance_deg`` 45 by default; F the figure, R a referent, C the context):

| words | true when |
|---|---|
| past, after, beyond | F lies on, beyond R, the line from C through R: angle between C->R and R->F <= tolerance |
| before, towards, toward | R lies past F (as above with F and R swapped): angle between C->F and F->R <= tolerance |
| left of / right of | angle at R from R->C to R->F is -90 / +90 deg +- tolerance (F on that hand, from C facing R) |
| beside, by, near, with, next to | F within ``near_m`` of R; a place "near here" must also lie behind the sign's face |
| between | the angle at F between F->R0 and F->R1 >= 180 - tolerance |
| in, inside, within | R is an ancestor of F in the hierarchy |

Arrows: the reader stands ``reading_m`` in front of the sign (or, when that is
within the robot's radius of a wall, at the first free cell farther out along
the normal, up to the reading range), at the centre of that route-grid cell. The route to a place is the shortest
collision-free path (the oracle's distance field, robot inflated) from there to
the nearest cell that can read a label of the place or of any place in it. Its
first leg is the first segment of the route simplified by ``simplify_m``
(Douglas-Peucker, shapely), a segment shorter than ``min_leg_m`` joined to the
next; a route shorter than ``min_leg_m`` (the label is readable from where the
reader stands) has as its first leg the line to the place's position. An arrow
is true when its direction (``prepositions.ARROWS`` added to the sign's facing)
is within ``tolerance_deg`` of the first leg.

That is how a building's wayfinding signs point: the way to set off. A
fingerpost (a park's, a zoo's, a campus's outdoor signs) points at the place
itself, as the crow flies. ``ARROW_READINGS`` holds both: ``way`` (the first
leg, the default) and ``bearing`` (the line from the reader to the place's
position; the place must still be reachable). A generated world records the
one its signs were written by (world.json's ``generator.arrows``, only when
it is not ``way``), and the check tests its arrows by that one.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np
from shapely.geometry import LineString

from abstract_map.hierarchy import Hierarchy
from abstract_map.prepositions import ARROWS, PREPOSITIONS, TABLE
from sim.world.data import Floorplan, Tag
from sim.world.oracle import OracleParams, distance_field, free_cells, pool_plan, readable_cells


@dataclass(frozen=True)
class TruthParams:
    """What the tests accept."""

    tolerance_deg: float = 45.0  # deg, for arrows and the angular prepositions (the 45 degrees)
    near_m: float = 6.0  # m, "near": 1.5 units at the paper's room-room scale (alpha 1-1 = 4 m)
    behind_m: float = 1.5  # m, a room's position behind its label: the middle of a 3 m deep room
    reading_m: float = 1.0  # m, a reader stands this far in front of a sign (mid-corridor)
    route_cell_m: float = 0.1  # m, the route grid (first legs need no finer; 4x fewer cells than the oracle's)
    robot_radius_m: float = 0.38  # m, the planner's and the oracle's inflation
    read_range_m: float = 4.0  # m, tags are read within this range
    cone_half_angle_deg: float = 45.0  # deg, about the tag's normal
    simplify_m: float = 0.3  # m, Douglas-Peucker tolerance for a route's legs
    min_leg_m: float = 0.6  # m, a shorter first segment is a jog, not a leg

    @property
    def oracle(self) -> OracleParams:
        return OracleParams(cell_m=self.route_cell_m, robot_radius_m=self.robot_radius_m,
                            read_range_m=self.read_range_m, cone_half_angle_deg=self.cone_half_angle_deg)


WALL_SNAP_M = 0.2  # m, the scene's tag_through_m and tag_snap_m: how far a tag may be drawn from its wall face
TAG_GAP_M = 0.02  # m, the scene's tag_wall_gap_m: a tag's face in front of its wall


def hang(plan: Floorplan, tag: Tag) -> tuple[Tag, str | None]:
    """Where ``tag`` hangs, by the scene's rule on the floor plan, and what is wrong if it has no wall.

    Along the tag's normal: a wall that starts within 0.2 m ahead of the drawn
    point (the point inside it, or behind a thin wall) and ends within 0.2 m
    after that carries the tag on its far face; failing that, a wall within
    0.2 m behind carries it on its near face. The tag hangs ``TAG_GAP_M`` in
    front of that face. With no such wall it stands where it is drawn.
    """
    n = np.array([math.cos(tag.theta), math.sin(tag.theta)])
    origin = np.array([tag.x, tag.y])
    step = min(0.01, plan.resolution / 2)
    ahead = np.arange(0.0, 2 * WALL_SNAP_M + step, step)
    occ = plan.wall_at(origin + ahead[:, None] * n)
    face: float | None = None
    starts = np.nonzero(occ & (ahead <= WALL_SNAP_M))[0]
    if len(starts):
        ends = np.nonzero(~occ[starts[0]:])[0]
        if len(ends) and ahead[starts[0] + ends[0]] - ahead[starts[0]] <= WALL_SNAP_M:
            face = float(ahead[starts[0] + ends[0]])
        elif occ[0]:
            return tag, f"inside a wall: no free face within {WALL_SNAP_M} m in front of it"
    if face is None:
        behind = np.arange(step, WALL_SNAP_M + step, step)
        hits = np.nonzero(plan.wall_at(origin - behind[:, None] * n))[0]
        if len(hits) == 0:
            return tag, f"no wall within {WALL_SNAP_M} m behind it (it stands free)"
        face = -float(behind[hits[0]]) + step
    x, y = origin + (face + TAG_GAP_M) * n
    return Tag(tag.id, float(x), float(y), tag.theta, tag.kind, tag.text), None


def angle_between(a: np.ndarray, b: np.ndarray) -> float:
    """Unsigned angle (deg) between two 2-vectors."""
    return abs(math.degrees(signed_angle(a, b)))


def signed_angle(a: np.ndarray, b: np.ndarray) -> float:
    """Counter-clockwise angle (rad, -pi..pi) from vector a to vector b."""
    return math.atan2(a[0] * b[1] - a[1] * b[0], a[0] * b[0] + a[1] * b[1])


@dataclass
class Facts:
    """What the tests look at: place positions (m) and the hierarchy."""

    positions: dict[str, np.ndarray]
    hierarchy: Hierarchy
    params: TruthParams = field(default_factory=TruthParams)
    facing: dict[str, float] = field(default_factory=dict)  # sign anchor name -> facing (rad)

    def ancestors(self, name: str) -> list[str]:
        out, node = [], self.hierarchy.parent.get(name)
        while node is not None:
            out.append(node)
            node = self.hierarchy.parent.get(node)
        return out


def place_positions(hierarchy: Hierarchy, tags: Mapping[int, Tag], behind_m: float) -> dict[str, np.ndarray]:
    """Every place's position (m) as defined in the module docstring; places with none are left out."""
    labels: dict[str, list[np.ndarray]] = {}
    for tag in tags.values():
        if tag.kind == "label":
            back = np.array([tag.x, tag.y]) - behind_m * np.array([math.cos(tag.theta), math.sin(tag.theta)])
            labels.setdefault(tag.text, []).append(back)
    kids: dict[str, list[str]] = {}
    for child, parent in hierarchy.parent.items():
        kids.setdefault(parent, []).append(child)
    positions: dict[str, np.ndarray] = {}

    def visit(name: str) -> np.ndarray | None:
        if name in positions:
            return positions[name]
        if name in labels:
            pos = np.mean(labels[name], axis=0)
        else:
            found = [p for p in (visit(c) for c in kids.get(name, [])) if p is not None]
            pos = np.mean(found, axis=0) if found else None
        if pos is not None:
            positions[name] = pos
        return pos

    for name in list(hierarchy.places) + sorted(set(labels) - set(hierarchy.places)):
        visit(name)
    return positions


# -- the preposition tests ---------------------------------------------------------------------
# Each returns None when the phrase is true, else a short reason. ``slack`` (<= 1) tightens the
# tolerance: the generator writes with slack 0.7 so that the check (slack 1) passes with room to spare.

Test = Callable[[Facts, str, tuple[str, ...], str, float], "str | None"]


def _pos(facts: Facts, *names: str) -> list[np.ndarray]:
    return [facts.positions[n] for n in names]


def _past(facts: Facts, fig: str, refs: tuple[str, ...], ctx: str, slack: float) -> str | None:
    f, r, c = _pos(facts, fig, refs[0], ctx)
    err = angle_between(r - c, f - r)
    limit = slack * facts.params.tolerance_deg
    return None if err <= limit else f"{fig} is {err:.0f} deg off the line from {ctx} through {refs[0]} (> {limit:.0f})"


def _before(facts: Facts, fig: str, refs: tuple[str, ...], ctx: str, slack: float) -> str | None:
    f, r, c = _pos(facts, fig, refs[0], ctx)
    err = angle_between(f - c, r - f)
    limit = slack * facts.params.tolerance_deg
    return None if err <= limit else f"{refs[0]} is {err:.0f} deg off the line from {ctx} through {fig} (> {limit:.0f})"


def _side(sign: float, word: str) -> Test:
    def test(facts: Facts, fig: str, refs: tuple[str, ...], ctx: str, slack: float) -> str | None:
        f, r, c = _pos(facts, fig, refs[0], ctx)
        angle = math.degrees(signed_angle(c - r, f - r))
        err = abs(angle - sign * 90.0)
        limit = slack * facts.params.tolerance_deg
        if err <= limit:
            return None
        return (f"from {ctx} facing {refs[0]}, {fig} is at {angle:+.0f} deg, "
                f"not {word} ({sign * 90:+.0f} +- {limit:.0f})")
    return test


def _near(facts: Facts, fig: str, refs: tuple[str, ...], ctx: str, slack: float) -> str | None:
    f, r = _pos(facts, fig, refs[0])
    d = float(np.hypot(*(f - r)))
    limit = slack * facts.params.near_m
    if d > limit:
        return f"{fig} is {d:.1f} m from {refs[0]} (> {limit:.1f} m)"
    if refs[0] in facts.facing:  # "near here": behind the sign's face, as a label's place
        n = np.array([math.cos(facts.facing[refs[0]]), math.sin(facts.facing[refs[0]])])
        if float(np.dot(f - r, n)) > 0.0:
            return f"{fig} is in front of the sign, not behind it"
    return None


def _between(facts: Facts, fig: str, refs: tuple[str, ...], ctx: str, slack: float) -> str | None:
    f, a, b = _pos(facts, fig, refs[0], refs[1])
    angle = angle_between(a - f, b - f)
    limit = 180.0 - slack * facts.params.tolerance_deg
    if angle >= limit:
        return None
    return f"{refs[0]} and {refs[1]} are {angle:.0f} deg apart seen from {fig} (< {limit:.0f})"


def _in(facts: Facts, fig: str, refs: tuple[str, ...], ctx: str, slack: float) -> str | None:
    return None if refs[0] in facts.ancestors(fig) else f"the hierarchy does not put {fig} in {refs[0]}"


TRUTH: dict[str, Test] = {
    # keyed by the first word of each row of abstract_map.prepositions.PREPOSITIONS
    "past": _past,
    "before": _before,
    "left of": _side(-1.0, "left of"),
    "right of": _side(+1.0, "right of"),
    "beside": _near,
    "between": _between,
    "in": _in,
}
GEOMETRIC = {"in": False}  # rows whose test needs no positions


def row_key(word: str) -> str:
    """The TRUTH key for any preposition word of the grammar."""
    return TABLE[word.lower()].words[0]


def phrase_verdict(facts: Facts, preposition: str, figure: str, referents: tuple[str, ...],
                   context: str | None, *, slack: float = 1.0) -> str | None:
    """None when the phrase is true, else why not (including a name with no known position)."""
    key = row_key(preposition)
    if GEOMETRIC.get(key, True):
        needed = [figure, *referents] + ([context] if context is not None and key in ("past", "before", "left of",
                                                                                        "right of") else [])
        missing = [n for n in needed if n not in facts.positions]
        if missing:
            return f"no position for {', '.join(repr(m) for m in missing)} (no label, nothing in it labelled)"
        if key in ("past", "before", "left of", "right of") and context is None:
            return "no context to read the phrase from"
    return TRUTH[key](facts, figure, referents, context or "", slack)


def _check_table() -> None:
    keys = {row.words[0] for row in PREPOSITIONS}
    if keys != set(TRUTH):
        raise RuntimeError(f"truth table rows {sorted(TRUTH)} do not match the prepositions {sorted(keys)}")


_check_table()


# -- routes and arrows -------------------------------------------------------------------------------

def arrow_direction(sign_theta: float, arrow: str) -> float:
    """World direction (rad) an arrow on a sign facing ``sign_theta`` points, per ``prepositions.ARROWS``."""
    return math.remainder(sign_theta + ARROWS[arrow.upper()], math.tau)


def nearest_arrow(sign_theta: float, direction: float) -> tuple[str, float]:
    """The arrow closest to ``direction`` (rad) and its error (deg)."""
    errors = {a: abs(math.degrees(math.remainder(direction - arrow_direction(sign_theta, a), math.tau)))
              for a in ARROWS}
    best = min(sorted(errors), key=lambda a: errors[a])
    return best, errors[best]


class Routes:
    """Shortest collision-free routes on a floor plan, the robot inflated: the oracle's machinery on the route grid."""

    def __init__(self, plan: Floorplan, params: TruthParams | None = None) -> None:
        self.params = params or TruthParams()
        self.grid = pool_plan(plan, self.params.route_cell_m)
        self.free = free_cells(self.grid, self.params.robot_radius_m)
        self._readable: dict[tuple[int, float, float, float], np.ndarray] = {}  # tag pose -> readable free cells

    def readable(self, tag: Tag) -> np.ndarray:
        """(row, col) of the free cells that can read ``tag`` (cached by tag pose)."""
        key = (tag.id, tag.x, tag.y, tag.theta)
        if key not in self._readable:
            self._readable[key] = np.argwhere(readable_cells(self.grid, tag, self.params.oracle) & self.free)
        return self._readable[key]

    def cell(self, xy: np.ndarray) -> tuple[int, int] | None:
        rc = self.grid.world_to_pixel(np.asarray(xy, dtype=float))[0]
        rows, cols = self.free.shape
        if 0 <= rc[0] < rows and 0 <= rc[1] < cols and self.free[rc[0], rc[1]]:
            return int(rc[0]), int(rc[1])
        return None

    def reading_pose(self, tag: Tag) -> np.ndarray | None:
        """Where a reader of ``tag`` stands (see the module docstring), or None when no free cell is in front."""
        n = np.array([math.cos(tag.theta), math.sin(tag.theta)])
        origin = np.array([tag.x, tag.y])
        steps = [self.params.reading_m] + list(np.arange(self.params.robot_radius_m, self.params.read_range_m,
                                                         self.grid.resolution / 2))
        for s in steps:
            cell = self.cell(origin + s * n)
            if cell is not None:
                return self.grid.pixel_to_world(np.array([cell]))[0]  # the cell's centre: robust to mm shifts
        return None

    def field_from(self, xy: np.ndarray) -> RouteField | None:
        cell = self.cell(xy)
        if cell is None:
            return None
        cumulative, mcp = distance_field(self.free, [cell])
        return RouteField(self, np.asarray(xy, dtype=float), cumulative, mcp)


@dataclass
class RouteField:
    """Distances from one point (a reader, the start) over the route grid."""

    routes: Routes
    origin: np.ndarray
    cumulative: np.ndarray
    mcp: object

    def _nearest(self, tag: Tag) -> tuple[float, tuple[int, int]] | None:
        cells = self.routes.readable(tag)
        if len(cells) == 0:
            return None
        costs = self.cumulative[cells[:, 0], cells[:, 1]]
        i = int(np.argmin(costs))
        return (float(costs[i]), (int(cells[i, 0]), int(cells[i, 1]))) if np.isfinite(costs[i]) else None

    def route_to(self, tags: list[Tag]) -> np.ndarray | None:
        """The shortest route (N, 2) m to a cell reading any of ``tags``, or None when none is reachable."""
        best: tuple[float, tuple[int, int]] | None = None
        for tag in tags:
            found = self._nearest(tag)
            if found is not None and (best is None or found[0] < best[0]):
                best = found
        if best is None:
            return None
        cells = np.array(self.mcp.traceback(best[1]))  # type: ignore[attr-defined]
        path = self.routes.grid.pixel_to_world(cells)
        path[0] = self.origin
        return path

    def reaches(self, tag: Tag) -> bool:
        return self._nearest(tag) is not None


def bearing(path: np.ndarray, target: np.ndarray | None, params: TruthParams) -> float | None:
    """Direction (rad) from a route's start (the reader) to the place's position ``target``; None without one."""
    if target is None:
        return None
    d = np.asarray(target) - path[0]
    return math.atan2(d[1], d[0]) if np.hypot(*d) > 1e-6 else None


def first_leg(path: np.ndarray, target: np.ndarray | None, params: TruthParams) -> float | None:
    """Direction (rad) of a route's first leg (module docstring); None if it has none."""
    length = float(np.hypot(*np.diff(path, axis=0).T).sum()) if len(path) > 1 else 0.0
    if length < params.min_leg_m:
        return bearing(path, target, params)
    coords = np.asarray(LineString(path).simplify(params.simplify_m).coords)
    end = coords[1]
    for point in coords[1:]:
        end = point
        if np.hypot(*(point - coords[0])) >= params.min_leg_m:
            break
    d = end - coords[0]
    return math.atan2(d[1], d[0])


def place_tags(name: str, hierarchy: Hierarchy, tags: Mapping[int, Tag]) -> list[Tag]:
    """Label tags of ``name`` and of every place in it: reading any of them means you have reached it."""
    inside = {name}
    grew = True
    while grew:
        more = {c for c, p in hierarchy.parent.items() if p in inside} - inside
        grew = bool(more)
        inside |= more
    return [t for t in tags.values() if t.kind == "label" and t.text in inside]


@dataclass(frozen=True)
class ArrowReading:
    """What a sign's arrow points along, given the reader's route to the place and the place's position."""

    describes: str  # the direction's name in the check's findings
    direction: Callable[[np.ndarray, np.ndarray | None, TruthParams], float | None]  # (route (N, 2) m, place m) -> rad


ARROW_READINGS: dict[str, ArrowReading] = {
    "way": ArrowReading("the route's first leg", first_leg),  # wayfinding signs in a building: the way to set off
    "bearing": ArrowReading("the place's bearing", bearing),  # fingerposts: the place as the crow flies
}
DEFAULT_ARROWS = "way"  # what a world that declares nothing (the zoo, a hand-made world) is checked by
