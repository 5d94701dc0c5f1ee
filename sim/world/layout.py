"""A building's plan in metres: a lattice of corridors, blocks of rooms between them, halls and doors.

Corridors run along the interior lines of a lattice (``Size.cells`` blocks
across and up); each stretch between two crossings is a segment of a networkx
graph. Segments are cut at random while the graph stays connected, keeps a
loop and a dead end, and every block keeps a corridor: what remains has T, L
and cross junctions, loops, and dead ends at the outer wall. A cut segment's
floor goes to one of the two blocks beside it.

A block is cut into rooms by a squarified treemap (``squarify``); a room on a
corridor gets a door onto it, the others a door into a neighbouring room that
leads there (rooms reached through rooms). A hall block is an open hall with
an exit onto each corridor beside it and a row of rooms along one side.

All coordinates are multiples of 0.1 m; walls are 0.2 m thick, doors 1 m wide
(the inflated robot, 0.38 m, clears a 1 m door by 0.12 m on each side).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import networkx as nx
import numpy as np
import squarify
from shapely.geometry import LineString, box

from sim.world.styles import Size, Style

WALL_M = 0.2  # m, wall thickness
HALF_WALL_M = WALL_M / 2
SNAP_M = 0.1  # m, every coordinate is a multiple of this
RESOLUTION_M = 0.05  # m per pixel of the floor plan
DOOR_M = 1.0  # m, door width
EXIT_M = 2.0  # m, a hall's exit onto a corridor
DOOR_WALL_M = 2.4  # m, shortest wall that takes a door and a label beside it
LABEL_OFFSET_M = 0.85  # m, door centre to label centre along the wall (half a door, a gap, half a tag)
TAG_FRONT_M = 0.02  # m, a tag's centre in front of its wall face (the scene's gap: it hangs where it is drawn)
HALL_STRIP_M = 4.6  # m, depth of the row of rooms along a hall
MIN_HALL_SIDE_M = 11.0  # m, a hall block this big on both sides gets a row of rooms
MIN_BLOCK_M = 4.0  # m, the narrowest block two corridors may leave between their lattice lines (a 2.6 m room,
# its walls and a margin); only the park's wide paths in a small building reach it, so no other style's
# buildings change

Node = tuple[int, int]
Edge = tuple[Node, Node]
RectT = tuple[float, float, float, float]  # x0, y0, x1, y1 (m)


def snap(v: float, step: float = SNAP_M) -> float:
    return round(round(v / step) * step, 6)


def inside_walls(rect: RectT) -> RectT:
    """The free part (m) of a room or hall whose ``rect`` runs to the middle of its walls."""
    x0, y0, x1, y1 = rect
    return (x0 + HALF_WALL_M, y0 + HALF_WALL_M, x1 - HALF_WALL_M, y1 - HALF_WALL_M)


def edge_key(a: Node, b: Node) -> Edge:
    return (a, b) if a <= b else (b, a)


@dataclass
class Opening:
    """A door or a hall exit: a gap in a wall, and the label beside it on the reader's side."""

    centre: tuple[float, float]  # m, on the wall's mid-line
    normal: tuple[float, float]  # unit, towards the side the label is read from
    width: float  # m
    place: str  # what the label beside it names
    label_side: int  # +1 / -1: the label is that way along the wall's tangent (normal turned +90 deg)

    @property
    def tangent(self) -> tuple[float, float]:
        return (-self.normal[1], self.normal[0])

    def carve(self) -> RectT:
        """The gap through the wall."""
        (cx, cy), (nx_, ny_), (tx, ty) = self.centre, self.normal, self.tangent
        half_w, half_t = self.width / 2, HALF_WALL_M
        xs = [cx + s * half_w * tx + u * half_t * nx_ for s in (-1, 1) for u in (-1, 1)]
        ys = [cy + s * half_w * ty + u * half_t * ny_ for s in (-1, 1) for u in (-1, 1)]
        return (min(xs), min(ys), max(xs), max(ys))

    def label_pose(self) -> tuple[float, float, float]:
        """(x, y, theta) of the label: beside the gap, just in front of the wall face, facing the reader."""
        (cx, cy), (nx_, ny_), (tx, ty) = self.centre, self.normal, self.tangent
        along = self.label_side * (self.width / 2 + LABEL_OFFSET_M - DOOR_M / 2)
        out = HALF_WALL_M + TAG_FRONT_M
        return (cx + along * tx + out * nx_, cy + along * ty + out * ny_, math.atan2(ny_, nx_))


@dataclass
class Room:
    name: str
    area: str
    rect: RectT  # m, up to the middle of its walls
    block: Node
    door: Opening | None = None
    via: str | None = None  # the room its door opens into (None: a corridor or the hall)
    edge: Edge | None = None  # the corridor segment it opens onto, through ``via`` if need be
    hall: str | None = None  # the hall it opens into

    @property
    def free(self) -> RectT:
        return inside_walls(self.rect)


@dataclass
class Hall:
    name: str
    rect: RectT
    block: Node
    exits: list[Opening] = field(default_factory=list)
    edges: list[Edge] = field(default_factory=list)

    @property
    def free(self) -> RectT:
        return inside_walls(self.rect)


@dataclass
class Layout:
    width: float  # m
    height: float  # m
    xs: list[float]  # m, lattice line x
    ys: list[float]  # m, lattice line y
    widths_x: dict[int, float]  # m, corridor width on vertical line i
    widths_y: dict[int, float]  # m, corridor width on horizontal line j
    graph: nx.Graph  # kept corridor segments; nodes carry "xy"
    entrance: Edge
    start: tuple[float, float, float]  # x m, y m, heading rad
    blocks: dict[Node, RectT]
    area_of_block: dict[Node, str]
    rooms: list[Room]
    halls: list[Hall]
    corridor_sides: dict[Node, dict[str, LineString]] = field(default_factory=dict)  # block -> side -> corridor wall

    def node_xy(self, node: Node) -> tuple[float, float]:
        return (self.xs[node[0]], self.ys[node[1]])

    def corridor_rects(self) -> list[RectT]:
        out = []
        inner = (WALL_M, WALL_M, self.width - WALL_M, self.height - WALL_M)
        for a, b in self.graph.edges:
            (xa, ya), (xb, yb) = self.node_xy(a), self.node_xy(b)
            if a[0] == b[0]:  # vertical segment
                h = self.widths_x[a[0]] / 2
                r = (xa - h, min(ya, yb), xa + h, max(ya, yb))
            else:
                h = self.widths_y[a[1]] / 2
                r = (min(xa, xb), ya - h, max(xa, xb), ya + h)
            out.append((max(r[0], inner[0]), max(r[1], inner[1]), min(r[2], inner[2]), min(r[3], inner[3])))
        return out

    def free_rects(self) -> list[RectT]:
        rects = self.corridor_rects() + [r.free for r in self.rooms] + [h.free for h in self.halls]
        rects += [r.door.carve() for r in self.rooms if r.door is not None]
        rects += [e.carve() for h in self.halls for e in h.exits]
        return rects

    def raster(self) -> np.ndarray:
        """Grey floor plan (rows, cols) uint8, row 0 at the top: 0 wall, 255 free."""
        cols, rows = round(self.width / RESOLUTION_M), round(self.height / RESOLUTION_M)
        image = np.zeros((rows, cols), dtype=np.uint8)
        for x0, y0, x1, y1 in self.free_rects():
            c0, c1 = round(x0 / RESOLUTION_M), round(x1 / RESOLUTION_M)
            r0, r1 = rows - round(y1 / RESOLUTION_M), rows - round(y0 / RESOLUTION_M)
            image[max(r0, 0):max(r1, 0), max(c0, 0):max(c1, 0)] = 255
        return image


# -- the corridor lattice ------------------------------------------------------------------------------

def _lines(rng: np.random.Generator, count: int, cell_m: tuple[float, float]) -> list[float]:
    out = [0.0]
    for _ in range(count):
        out.append(snap(out[-1] + rng.uniform(*cell_m), 0.2))
    return out


def _lattice(nx_: int, ny: int) -> nx.Graph:
    g = nx.Graph()
    for i in range(1, nx_):
        for j in range(ny):
            g.add_edge((i, j), (i, j + 1))
    for j in range(1, ny):
        for i in range(nx_):
            g.add_edge((i, j), (i + 1, j))
    return g


def block_sides(block: Node) -> dict[str, Edge]:
    """The lattice segments along each side of a block (some lie on the outer wall and never exist)."""
    i, j = block
    return {"left": edge_key((i, j), (i, j + 1)), "right": edge_key((i + 1, j), (i + 1, j + 1)),
            "bottom": edge_key((i, j), (i + 1, j)), "top": edge_key((i, j + 1), (i + 1, j + 1))}


def _cut_segments(g: nx.Graph, blocks: list[Node], entrance: Edge, fraction: float,
                  rng: np.random.Generator) -> nx.Graph:
    kept = g.copy()
    edges = sorted(kept.edges)
    order = rng.permutation(len(edges))
    target = round(fraction * len(edges))
    removed = 0
    for k in order:
        if removed >= target:
            break
        e = edge_key(*edges[k])
        if e == entrance:
            continue
        trial = kept.copy()
        trial.remove_edge(*e)
        trial.remove_nodes_from([n for n in list(trial.nodes) if trial.degree(n) == 0])
        if entrance[0] not in trial or not nx.is_connected(trial) or not nx.cycle_basis(trial):
            continue
        if not any(trial.degree(n) == 1 for n in trial.nodes if n not in entrance):
            continue
        if not all(any(trial.has_edge(*s) for s in block_sides(b).values()) for b in blocks):
            continue
        kept, removed = trial, removed + 1
    return kept


# -- blocks, rooms and doors -----------------------------------------------------------------------------

def _block_rects(layout_lines: tuple[list[float], list[float]], wx: dict[int, float], wy: dict[int, float],
                 kept: nx.Graph, blocks: list[Node], rng: np.random.Generator) -> dict[Node, RectT]:
    xs, ys = layout_lines
    owner: dict[Edge, Node] = {}
    for e in sorted(_lattice(len(xs) - 1, len(ys) - 1).edges):
        e = edge_key(*e)
        if kept.has_edge(*e):
            continue
        (i0, j0), (i1, j1) = e
        beside = [(i0 - 1, j0), (i0, j0)] if i0 == i1 else [(i0, j0 - 1), (i0, j0)]
        beside = [b for b in beside if b in blocks]
        owner[e] = beside[int(rng.integers(len(beside)))]
    rects: dict[Node, RectT] = {}
    for b in blocks:
        i, j = b
        sides = block_sides(b)

        def side(line: int, coords: list[float], widths: dict[int, float], e: Edge, sign: float,
                 b: Node = b) -> float:
            if line == 0:
                return HALF_WALL_M
            if line == len(coords) - 1:
                return coords[-1] - HALF_WALL_M
            half = widths[line] / 2 + HALF_WALL_M
            grow = owner.get(e) == b
            return snap(coords[line] + (-sign if grow else sign) * half)

        rects[b] = (side(i, xs, wx, sides["left"], 1), side(j, ys, wy, sides["bottom"], 1),
                    side(i + 1, xs, wx, sides["right"], -1), side(j + 1, ys, wy, sides["top"], -1))
    return rects


def _side_lines(rect: RectT) -> dict[str, LineString]:
    x0, y0, x1, y1 = rect
    return {"left": LineString([(x0, y0), (x0, y1)]), "right": LineString([(x1, y0), (x1, y1)]),
            "bottom": LineString([(x0, y0), (x1, y0)]), "top": LineString([(x0, y1), (x1, y1)])}


_OUTWARD = {"left": (-1.0, 0.0), "right": (1.0, 0.0), "bottom": (0.0, -1.0), "top": (0.0, 1.0)}


def _shared(a: RectT, line: LineString) -> LineString | None:
    inter = box(*a).boundary.intersection(line)
    if inter.is_empty or inter.geom_type != "LineString" or inter.length < DOOR_WALL_M - 1e-6:
        return None
    return inter


def _opening(segment: LineString, normal: tuple[float, float], width: float, place: str,
             rng: np.random.Generator) -> Opening:
    """A gap of ``width`` somewhere along ``segment`` (a wall's mid-line), its label beside it."""
    (ax, ay), (bx, by) = segment.coords[0], segment.coords[-1]
    tangent = (-normal[1], normal[0])
    s0, s1 = sorted((ax * tangent[0] + ay * tangent[1], bx * tangent[0] + by * tangent[1]))
    side = 1 if rng.random() < 0.5 else -1
    margin = HALF_WALL_M + 0.1  # keep clear of the perpendicular wall
    label_reach = width / 2 + LABEL_OFFSET_M - DOOR_M / 2 + 0.2  # to the far edge of the label
    lo, hi = (s0 + margin + width / 2, s1 - margin - label_reach) if side > 0 else \
        (s0 + margin + label_reach, s1 - margin - width / 2)
    if hi < lo:  # too short for the label on that side: centre the gap, label on the longer side
        lo = hi = (s0 + s1) / 2
    along = snap(rng.uniform(lo, hi)) if hi > lo else snap(lo)
    across = ax * normal[0] + ay * normal[1]
    centre = (along * tangent[0] + across * normal[0], along * tangent[1] + across * normal[1])
    return Opening((snap(centre[0], 0.05), snap(centre[1], 0.05)), normal, width, place, side)


def _treemap(rect: RectT, n: int, rng: np.random.Generator) -> list[RectT]:
    x0, y0, x1, y1 = rect
    weights = sorted(rng.uniform(0.6, 1.4, n), reverse=True)
    cells = squarify.squarify(squarify.normalize_sizes(weights, x1 - x0, y1 - y0), x0, y0, x1 - x0, y1 - y0)
    return [(snap(c["x"]), snap(c["y"]), snap(c["x"] + c["dx"]), snap(c["y"] + c["dy"])) for c in cells]


@dataclass
class _Namer:
    style: Style
    rng: np.random.Generator
    used: set[str] = field(default_factory=set)

    def room(self, area: str) -> str:
        prefix = area.split()[0]
        base = f"{prefix} {self.style.rooms[int(self.rng.integers(len(self.style.rooms)))]}"
        name, k = base, 2
        while name in self.used:
            name, k = f"{base} {k}", k + 1
        self.used.add(name)
        return name


def _rooms_in_block(block: Node, rect: RectT, area: str, corridor_sides: dict[str, LineString], style: Style,
                    namer: _Namer, rng: np.random.Generator) -> list[Room]:
    """Treemap the block into as many rooms as fit; every room gets a door (corridor or a neighbour)."""
    dx, dy = rect[2] - rect[0], rect[3] - rect[1]
    n = max(1, round(dx * dy / style.room_m2))
    while True:
        cells = _treemap(rect, n, rng)
        small = any(min(c[2] - c[0], c[3] - c[1]) < style.min_room_side_m for c in cells)
        rooms = None if small and n > 1 else _connect(cells, corridor_sides, rng)
        if rooms is not None:
            break
        n -= 1
    out = []
    for cell, (door_seg, normal, via, side_name) in zip(cells, rooms):
        room = Room(namer.room(area), area, cell, block)
        room.door = _opening(door_seg, normal, DOOR_M, room.name, rng)
        room.via = via  # index of the room it opens into, resolved below
        room.edge = side_name  # the corridor side's name, resolved by the caller
        out.append(room)
    for room in out:
        if room.via is not None:
            room.via = out[int(room.via)].name
    return out


def _connect(cells: list[RectT], corridor_sides: dict[str, LineString], rng: np.random.Generator):  # type: ignore[no-untyped-def]
    """For each cell: (door segment, reader-side normal, index of the room it opens into or None, side name)."""
    g = nx.Graph()
    direct: dict[int, tuple[LineString, tuple[float, float], str]] = {}
    for k, c in enumerate(cells):
        g.add_node(k)
        options = [(seg, _OUTWARD[name], name) for name, line in sorted(corridor_sides.items())
                   if (seg := _shared(c, line)) is not None]
        if options:
            direct[k] = max(options, key=lambda o: o[0].length)
    for a in range(len(cells)):
        for b in range(a + 1, len(cells)):
            inter = box(*cells[a]).intersection(box(*cells[b]))
            if inter.geom_type == "LineString" and inter.length >= DOOR_WALL_M - 1e-6:
                g.add_edge(a, b, segment=inter)
    if not direct:
        return None
    out: list = [None] * len(cells)
    for k, (seg, normal, name) in direct.items():
        out[k] = (seg, normal, None, name)
    frontier = sorted(direct)
    seen = set(frontier)
    while frontier:
        nxt = []
        for k in frontier:
            for m in sorted(g.neighbors(k)):
                if m in seen:
                    continue
                seen.add(m)
                seg = g.edges[k, m]["segment"]
                ck, cm = box(*cells[k]).centroid, box(*cells[m]).centroid
                horizontal = abs(seg.coords[0][1] - seg.coords[-1][1]) < 1e-9
                normal = (0.0, 1.0 if ck.y > cm.y else -1.0) if horizontal else (1.0 if ck.x > cm.x else -1.0, 0.0)
                out[m] = (seg, normal, k, None)
                nxt.append(m)
        frontier = nxt
    return None if any(o is None for o in out) else out


def _hall_block(block: Node, rect: RectT, hall_name: str, area: str, corridor_sides: dict[str, LineString],
                namer: _Namer, rng: np.random.Generator) -> tuple[Hall, list[Room]]:
    x0, y0, x1, y1 = rect
    rooms: list[Room] = []
    hall_rect = rect
    if min(x1 - x0, y1 - y0) >= MIN_HALL_SIDE_M:
        quiet = [s for s in ("top", "bottom", "left", "right") if s not in corridor_sides]
        strip_side = quiet[0] if quiet else ("top" if "top" not in corridor_sides else sorted(corridor_sides)[0])
        d = HALL_STRIP_M
        strip, hall_rect = {
            "top": ((x0, snap(y1 - d), x1, y1), (x0, y0, x1, snap(y1 - d))),
            "bottom": ((x0, y0, x1, snap(y0 + d)), (x0, snap(y0 + d), x1, y1)),
            "left": ((x0, y0, snap(x0 + d), y1), (snap(x0 + d), y0, x1, y1)),
            "right": ((snap(x1 - d), y0, x1, y1), (x0, y0, snap(x1 - d), y1)),
        }[strip_side]
        length = (strip[2] - strip[0]) if strip_side in ("top", "bottom") else (strip[3] - strip[1])
        n = max(1, int(length // 4.5))
        inward = {"top": (0.0, -1.0), "bottom": (0.0, 1.0), "left": (1.0, 0.0), "right": (-1.0, 0.0)}[strip_side]
        for k in range(n):
            a, b = k / n, (k + 1) / n
            if strip_side in ("top", "bottom"):
                cell = (snap(strip[0] + a * length), strip[1], snap(strip[0] + b * length), strip[3])
            else:
                cell = (strip[0], snap(strip[1] + a * length), strip[2], snap(strip[1] + b * length))
            room = Room(namer.room(area), area, cell, block, hall=hall_name)
            seg = box(*cell).intersection(box(*hall_rect))
            room.door = _opening(seg, inward, DOOR_M, room.name, rng)
            rooms.append(room)
    hall = Hall(hall_name, hall_rect, block)
    for name, line in sorted(corridor_sides.items()):
        seg = _shared(hall_rect, line)
        if seg is not None:
            hall.exits.append(_opening(seg, _OUTWARD[name], EXIT_M, hall_name, rng))
    return hall, rooms


def build_layout(style: Style, size: Size, rng: np.random.Generator) -> Layout:
    """The plan of one building (module docstring). Names of areas are assigned here; wings by the caller."""
    nx_, ny = size.cells
    xs, ys = _lines(rng, nx_, size.cell_m), _lines(rng, ny, size.cell_m)
    hi = min(style.corridor_m[1], size.cell_m[0] - MIN_BLOCK_M)  # a wide path leaves a block between its lines
    lo = min(style.corridor_m[0], hi)

    def width() -> float:
        return min(hi, max(lo, snap(rng.uniform(lo, hi), 0.2)))

    wx = {i: width() for i in range(1, nx_)}
    wy = {j: width() for j in range(1, ny)}
    blocks = [(i, j) for j in range(ny) for i in range(nx_)]
    entrance_line = 1 + int(rng.integers(nx_ - 1))
    entrance = edge_key((entrance_line, 0), (entrance_line, 1))
    kept = _cut_segments(_lattice(nx_, ny), blocks, entrance, style.cut_fraction, rng)
    for n in kept.nodes:
        kept.nodes[n]["xy"] = (xs[n[0]], ys[n[1]])
    rects = _block_rects((xs, ys), wx, wy, kept, blocks, rng)

    # areas: blocks in serpentine order; with more blocks than names, neighbours share an area
    serpentine = [(i if j % 2 == 0 else nx_ - 1 - i, j) for j in range(ny) for i in range(nx_)]
    names = [style.areas[k] for k in rng.permutation(len(style.areas))]
    per = math.ceil(len(serpentine) / len(names))
    area_of = {b: names[k // per] for k, b in enumerate(serpentine)}

    # halls: blocks with the most corridor sides (several exits), away from the entrance block
    def corridor_sides(b: Node) -> dict[str, LineString]:
        """The block's sides on a corridor, clipped to the corridor's length (node centre to node centre)."""
        lines = _side_lines(rects[b])
        out = {}
        for name, e in block_sides(b).items():
            if not kept.has_edge(*e):
                continue
            (i0, j0), (i1, j1) = e
            if i0 == i1:
                clip = box(-1.0, max(ys[j0], WALL_M), xs[-1] + 1.0, min(ys[j1], ys[-1] - WALL_M))
            else:
                clip = box(max(xs[i0], WALL_M), -1.0, min(xs[i1], xs[-1] - WALL_M), ys[-1] + 1.0)
            seg = lines[name].intersection(clip)
            if seg.geom_type == "LineString" and seg.length > 0:
                out[name] = seg
        return out

    entrance_blocks = {(entrance_line - 1, 0), (entrance_line, 0)}
    ranked = sorted(blocks, key=lambda b: (-len(corridor_sides(b)), b in entrance_blocks, float(rng.random())))
    hall_blocks = [b for b in ranked if len(corridor_sides(b)) >= 2][: style.halls_per_building]
    hall_names = [style.halls[k] for k in rng.permutation(len(style.halls))]

    namer = _Namer(style, rng)
    rooms: list[Room] = []
    halls: list[Hall] = []
    for b in blocks:
        sides = corridor_sides(b)
        if b in hall_blocks:
            hall, strip = _hall_block(b, rects[b], hall_names[hall_blocks.index(b)], area_of[b], sides, namer, rng)
            hall.edges = [block_sides(b)[name] for name in sorted(sides)]
            halls.append(hall)
            rooms.extend(strip)
            continue
        for room in _rooms_in_block(b, rects[b], area_of[b], sides, style, namer, rng):
            room.edge = block_sides(b)[room.edge] if isinstance(room.edge, str) else None
            rooms.append(room)
    _resolve_edges(rooms)
    _force_through_rooms(rooms, style.through_rooms, rng)
    width_m, height_m = xs[-1], ys[-1]
    x_e = xs[entrance_line]
    start = (x_e, WALL_M + 1.2, math.pi / 2)
    return Layout(width_m, height_m, xs, ys, wx, wy, kept, entrance, start, rects, area_of, rooms, halls,
                  {b: corridor_sides(b) for b in blocks})


def _resolve_edges(rooms: list[Room]) -> None:
    by_name = {r.name: r for r in rooms}
    for room in rooms:
        node, seen = room, set()
        while node.via is not None and node.name not in seen:
            seen.add(node.name)
            node = by_name[node.via]
        room.edge = node.edge


def _force_through_rooms(rooms: list[Room], wanted: int, rng: np.random.Generator) -> None:
    """Make rooms reached only through a neighbour until ``wanted`` exist (where neighbours allow)."""
    have = sum(r.via is not None for r in rooms)
    by_name = {r.name: r for r in rooms}
    order = [rooms[k] for k in rng.permutation(len(rooms))]
    hosts: set[str] = {r.via for r in rooms if r.via}
    for room in order:
        if have >= wanted:
            return
        if room.via is not None or room.hall is not None or room.name in hosts:
            continue
        for other in order:
            if other is room or other.via is not None or other.hall is not None or other.block != room.block:
                continue
            inter = box(*room.rect).intersection(box(*other.rect))
            if inter.geom_type != "LineString" or inter.length < DOOR_WALL_M - 1e-6:
                continue
            horizontal = abs(inter.coords[0][1] - inter.coords[-1][1]) < 1e-9
            oc, rc = box(*other.rect).centroid, box(*room.rect).centroid
            normal = (0.0, 1.0 if oc.y > rc.y else -1.0) if horizontal else (1.0 if oc.x > rc.x else -1.0, 0.0)
            room.door = _opening(inter, normal, DOOR_M, room.name, rng)
            room.via, room.edge = other.name, other.edge
            hosts.add(other.name)
            have += 1
            break
    del by_name
