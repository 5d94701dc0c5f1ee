"""What a generated building says: where its signs hang and what they say, all true by ``truth``.

Signs hang at the entrance (on the entrance corridor's wall) and at every
junction of three or more corridors, facing the way a visitor from the
entrance arrives: on the far wall of a T, or on the corner across the junction
otherwise, always where the junction's centre sees the sign's reader (never on
a wall of a room behind the junction's own walls). Each names, by arrow, the
goals (or their areas) whose routes pass the junction, then a few more areas,
wings, halls and rooms; an arrow is written only when ``truth`` puts it well
within the tolerance (``slack``). Each sign also carries phrases (past,
before, left of, right of, near, between) that ``truth`` calls true with the
same slack, and an "X is in Y" line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from abstract_map.hierarchy import Hierarchy
from abstract_map.prepositions import PREPOSITIONS
from sim.world.data import Floorplan, Tag
from sim.world.layout import TAG_FRONT_M, Layout, Node
from sim.world.truth import (
    ARROW_READINGS,
    DEFAULT_ARROWS,
    ArrowReading,
    Facts,
    RouteField,
    Routes,
    hang,
    nearest_arrow,
    phrase_verdict,
    place_tags,
)

SLACK = 0.7  # the generator writes phrases true with 70 % of the check's tolerance
ARROW_SLACK = 40.0 / 45.0  # and arrows within 40 of the 45 degrees (routes are recomputed exactly by the check)
ARROW_ORDER = ("LEFT", "UP", "RIGHT", "DOWN")
PHRASE_ROWS = ("past", "before", "left of", "right of", "beside", "between")
NEARBY_M = 14.0  # m, phrases name places this close to the sign
EXTRA_NAMES = 3  # names a sign adds beyond the goals' (areas, wings, halls, rooms)


@dataclass
class SignSpot:
    x: float
    y: float
    theta: float  # rad
    node: Node | None  # the junction it serves (None: the entrance)
    alternates: list[SignSpot] = field(default_factory=list)  # other walls at the same junction, in preference order


@dataclass
class Sign:
    spot: SignSpot
    tag_id: int = -1
    arrows: dict[str, list[str]] = field(default_factory=dict)  # arrow -> names
    phrases: list[str] = field(default_factory=list)

    def text(self) -> str:
        lines = [f"${a}$ " + ", ".join(self.arrows[a]) for a in ARROW_ORDER if self.arrows.get(a)]
        return "\n".join(lines + self.phrases)

    def names(self) -> set[str]:
        return {n for names in self.arrows.values() for n in names}


def _wall_ok(plan: Floorplan, x: float, y: float, theta: float) -> bool:
    """A wall right behind (x, y) and free space in front, across the tag's width."""
    n = np.array([math.cos(theta), math.sin(theta)])
    t = np.array([-n[1], n[0]])
    origin = np.array([x, y])
    offsets = np.linspace(-0.25, 0.25, 11)
    behind = origin - (TAG_FRONT_M + 0.05) * n + offsets[:, None] * t
    front = origin + 0.3 * n + offsets[:, None] * t
    return bool(plan.wall_at(behind).all() and not plan.wall_at(front).any())


MIN_TAG_GAP_M = 0.6  # m, centre to centre: two tags (0.375 m wide with their quiet zones) never overlap


def in_sight(plan: Floorplan, a: tuple[float, float] | np.ndarray, b: tuple[float, float] | np.ndarray) -> bool:
    """Whether the segment from ``a`` to ``b`` (m) crosses no wall of ``plan`` (sampled every half pixel): a
    junction's sign is read from where the junction's centre can see, not from a room behind its wall."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    n = max(2, int(math.ceil(float(np.hypot(*(b - a))) / (0.5 * plan.resolution))) + 1)
    return not bool(plan.wall_at(a + np.linspace(0.0, 1.0, n)[:, None] * (b - a)).any())


def sign_spots(layout: Layout, plan: Floorplan, routes: Routes, labels: list[Tag]) -> list[SignSpot]:
    """The entrance sign and one sign per junction (three or more corridors), where a wall takes them.

    A spot needs a wall behind it, free space in front, a reading pose, and no
    label within ``MIN_TAG_GAP_M``.
    """
    taken = np.array([[t.x, t.y] for t in labels]).reshape(-1, 2)

    def fits(spot: SignSpot) -> bool:
        clear = len(taken) == 0 or float(np.hypot(*(taken - [spot.x, spot.y]).T).min()) >= MIN_TAG_GAP_M
        if not (clear and _wall_ok(plan, spot.x, spot.y, spot.theta)):
            return False
        pose = routes.reading_pose(_tag(spot, plan))
        return pose is not None and (spot.node is None or in_sight(plan, layout.node_xy(spot.node), pose))

    g = layout.graph
    entrance_node = min(layout.entrance)  # the end on the outer wall
    spots: list[SignSpot] = []
    x_e, y_s, _ = layout.start
    half = layout.widths_x[entrance_node[0]] / 2
    for dy in (2.0, 3.0, 4.0, 1.5, 5.0):
        for side in (1, -1):
            spot = SignSpot(round(x_e + side * (half - TAG_FRONT_M), 4), round(y_s + dy, 4),
                            math.pi if side > 0 else 0.0, None)
            if fits(spot):
                spots.append(spot)
                break
        if spots:
            break
    paths = _shortest_paths(g, entrance_node)
    for node in sorted(g.nodes):
        if g.degree(node) < 3 or node not in paths or len(paths[node]) < 2:
            continue
        prev = paths[node][-2]
        d = np.sign(np.subtract(node, prev)).astype(float)  # lattice steps are axis-aligned
        spot = _junction_spot(layout, node, d, fits)
        if spot is not None:
            spots.append(spot)
    return spots


def _shortest_paths(g, source):  # type: ignore[no-untyped-def]
    import networkx as nx

    def length(a: Node, b: Node, _: dict) -> float:
        return float(math.dist(g.nodes[a]["xy"], g.nodes[b]["xy"]))

    return nx.single_source_dijkstra_path(g, source, weight=length)


def _tag(spot: SignSpot, plan: Floorplan) -> Tag:
    """The sign's tag where the check and the scene hang it (its written position rounded as in tags.json)."""
    return hang(plan, Tag(-1, round(spot.x, 4), round(spot.y, 4), spot.theta, "sign", ""))[0]


def _junction_spot(layout: Layout, node: Node, d: np.ndarray, fits) -> SignSpot | None:  # type: ignore[no-untyped-def]
    """A wall for the sign at ``node``: facing the arrival direction ``d`` (the T's far wall, else a corner
    across the junction), else the far wall of the T facing its stem."""
    x, y = layout.node_xy(node)
    candidates: list[tuple[np.ndarray, float]] = []
    for k, way in enumerate([d] + [np.array(m, dtype=float) for m in ((1, 0), (-1, 0), (0, 1), (0, -1))]):
        vertical = way[0] == 0
        cross_half = layout.widths_y[node[1]] / 2 if vertical else layout.widths_x[node[0]] / 2
        along_half = layout.widths_x[node[0]] / 2 if vertical else layout.widths_y[node[1]] / 2
        theta = math.atan2(-way[1], -way[0])
        face = np.array([x, y]) + way * (cross_half + TAG_FRONT_M)
        ahead = (node[0] + int(way[0]), node[1] + int(way[1]))
        perp = np.array([-way[1], way[0]])
        if not layout.graph.has_edge(node, ahead):
            candidates += [(face + j * perp, theta) for j in (0.0, 0.7, -0.7, 1.4, -1.4, 2.1, -2.1)]
        if k == 0:  # corners only for the arrival direction
            candidates += [(face + p * (along_half + extra), theta) for p in (perp, -perp) for extra in (0.8, 1.4, 2.0)]
    found: list[SignSpot] = []
    for c, theta in candidates:
        spot = SignSpot(round(float(c[0]), 4), round(float(c[1]), 4), theta, node)
        if len(found) < 3 and fits(spot) and all(math.dist((spot.x, spot.y), (f.x, f.y)) > 0.5 for f in found):
            found.append(spot)
    if not found:
        return None
    found[0].alternates = found[1:]
    return found[0]


@dataclass
class Writer:
    """Writes signs' text from the truth tests, keeping count of which prepositions it has used."""

    facts: Facts
    routes: Routes
    plan: Floorplan
    tags: dict[int, Tag]  # the labels, where they hang
    rng: np.random.Generator
    reading: ArrowReading = ARROW_READINGS[DEFAULT_ARROWS]  # what an arrow points along (``truth.ARROW_READINGS``)
    used_rows: dict[str, int] = field(default_factory=lambda: {r: 0 for r in PHRASE_ROWS})
    used_words: dict[str, int] = field(default_factory=dict)
    _fields: dict[tuple[float, float, float], RouteField | None] = field(default_factory=dict)

    @property
    def hierarchy(self) -> Hierarchy:
        return self.facts.hierarchy

    def arrows(self, sign: Sign, names: list[str]) -> list[str]:
        """Add an arrow for each name that ``truth`` calls clearly true from this sign; return the names left out."""
        key = (sign.spot.x, sign.spot.y, sign.spot.theta)
        if key not in self._fields:
            pose = self.routes.reading_pose(_tag(sign.spot, self.plan))
            self._fields[key] = self.routes.field_from(pose) if pose is not None else None
        field_ = self._fields[key]
        skipped = []
        for name in names:
            if field_ is None or any(name in v for v in sign.arrows.values()):
                skipped.append(name)
                continue
            path = field_.route_to(place_tags(name, self.hierarchy, self.tags))
            leg = None if path is None else self.reading.direction(path, self.facts.positions.get(name),
                                                                    self.routes.params)
            if leg is None:
                skipped.append(name)
                continue
            arrow, error = nearest_arrow(sign.spot.theta, leg)
            if error > ARROW_SLACK * self.routes.params.tolerance_deg:
                skipped.append(name)
                continue
            sign.arrows.setdefault(arrow, []).append(name)
        return skipped

    def _word(self, row: str) -> str:
        words = next(r.words for r in PREPOSITIONS if r.words[0] == row)
        word = min(words, key=lambda w: (self.used_words.get(w, 0), words.index(w)))
        self.used_words[word] = self.used_words.get(word, 0) + 1
        return word

    def phrases(self, sign: Sign, anchor: str, count: int) -> None:
        """Add up to ``count`` true phrases about places near the sign, least-used prepositions first."""
        here = np.array([sign.spot.x, sign.spot.y])
        nearby = sorted(n for n, p in self.facts.positions.items()
                        if not n.startswith("#") and n not in self.hierarchy.roots()
                        and np.hypot(*(p - here)) <= NEARBY_M and not self.hierarchy.children(n))
        if len(nearby) < 2:
            return
        rows = sorted(PHRASE_ROWS, key=lambda r: (self.used_rows[r], float(self.rng.random())))
        written = 0
        for row in rows:
            if written >= count:
                break
            line = self._try_row(row, nearby, anchor)
            if line is not None:
                sign.phrases.append(line)
                self.used_rows[row] += 1
                written += 1

    def _try_row(self, row: str, nearby: list[str], anchor: str) -> str | None:
        n_refs = 2 if row == "between" else 1
        if len(nearby) < 1 + n_refs:  # "between" needs three places near the sign
            return None
        for _ in range(40):
            pick = [nearby[k] for k in self.rng.choice(len(nearby), size=1 + n_refs, replace=False)]
            fig, refs = pick[0], tuple(pick[1:])
            if row == "beside" and self.rng.random() < 0.4:
                refs = (anchor,)
            if phrase_verdict(self.facts, row, fig, refs, anchor, slack=SLACK) is None:
                word = self._word(row)
                if refs == (anchor,):
                    return f"The {fig} is {word} here"
                return f"The {fig} is {word} the " + " and the ".join(refs)
        return None

    def in_line(self, sign: Sign) -> str | None:
        """An "X is in Y" line about a place the sign names (or a room nearby)."""
        candidates = sorted(n for n in sign.names() if n in self.hierarchy.parent)
        if not candidates:
            return None
        fig = candidates[int(self.rng.integers(len(candidates)))]
        parent = self.hierarchy.parent[fig]
        if parent in self.hierarchy.roots():
            return None
        return f"The {fig} is {self._word('in')} {parent}"
