"""Generate a building in the world-folder format: plan, labels, signs, hierarchy, start and five goals.

``generate(seed, style=, size=, signage=, arrows=)`` is pure (no files): the
same arguments give the same bytes. ``arrows`` says what the signs' arrows
point along (``truth.ARROW_READINGS``): ``way``, the route's first leg, as a
building's wayfinding signs do (the default), or ``bearing``, the place
itself, as fingerposts do; the layout, labels and goals do not depend on it.
``write_world`` writes the folder atomically;
``generated_world`` writes it under a root once and returns it. The plan comes
from ``layout``, the signs from ``signage``, and everything the signs say is
true by ``truth`` (misleading signage excepted: its wrong arrows are listed in
world.json's ``generator.misleading``).

Goals: one behind a loop (its door on a corridor segment that lies on a cycle
of the corridor graph), one off a dead end (its door on a segment that ends at a
dead end), one named by no arrow (arrows name only its area), and two more
spread over other areas (a room off a hall, a room reached through a room, or
the farthest room left).
"""

from __future__ import annotations

import io
import json
import math
import os
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

import networkx as nx
import numpy as np

from abstract_map.hierarchy import Hierarchy
from sim.world.data import FORMAT, Floorplan, Tag, World
from sim.world.layout import (
    DOOR_M,
    RESOLUTION_M,
    Layout,
    Room,
    _opening,
    _shared,
    block_sides,
    build_layout,
)
from sim.world.oracle import oracle_paths
from sim.world.signage import EXTRA_NAMES, Sign, Writer, sign_spots
from sim.world.signage import _tag as _sign_tag
from sim.world.styles import SIGNAGE, SIZES, STYLES, Size, Style, lookup
from sim.world.truth import (
    ARROW_READINGS,
    DEFAULT_ARROWS,
    Facts,
    Routes,
    TruthParams,
    arrow_direction,
    hang,
    place_positions,
)

FILES = ("world.json", "floorplan.png", "tags.json", "hierarchy.xml")
N_TAG_IDS = 587  # AprilTag 36h11 has ids 0-586
N_GOALS = 5


@dataclass(frozen=True)
class GeneratedWorld:
    """A generated building: the folder's files as bytes, and what was made, for tests and callers."""

    name: str
    seed: int
    style: str
    size: str
    signage: str
    files: dict[str, bytes]  # file name -> content, exactly as write_world writes them
    world: World  # the same world in memory (root "."; its hierarchy is ``hierarchy``)
    hierarchy: Hierarchy
    layout: Layout
    goal_roles: dict[str, str]  # goal -> "loop" | "dead end" | "no arrow" | "hall" | "through room" | "far"
    misleading: list[dict[str, Any]]  # {"tag", "name", "arrow"}: arrows written wrong on purpose
    arrows: str = DEFAULT_ARROWS  # what the arrows point along (``truth.ARROW_READINGS``)

    def check(self):  # type: ignore[no-untyped-def]
        """``check_world`` on the world in memory (its hierarchy is not on disk): a ``CheckReport``."""
        from sim.world.check import check_world

        return check_world(self.world, hierarchy=self.hierarchy)


def world_name(seed: int, style: str, size: str, signage: str, arrows: str = DEFAULT_ARROWS) -> str:
    """``gen-STYLE-SIZE-SIGNAGE-SEED``, with ``-ARROWS`` before the seed when the arrows are not the default's."""
    reading = "" if arrows == DEFAULT_ARROWS else f"{arrows}-"
    return f"gen-{style}-{size}-{signage}-{reading}{seed}"


# -- hierarchy -------------------------------------------------------------------------------------------

def _hierarchy(style: Style, size: Size, layout: Layout, rng: np.random.Generator) -> dict[str, Any]:
    """Nested places: building > [wings >] areas > rooms; halls in their wing (or the building)."""
    areas: list[str] = []
    for b in sorted(layout.area_of_block, key=lambda b: (b[1], b[0] if b[1] % 2 == 0 else -b[0])):
        if layout.area_of_block[b] not in areas:
            areas.append(layout.area_of_block[b])
    rooms_of: dict[str, list[str]] = {a: [r.name for r in layout.rooms if r.area == a] for a in areas}
    areas = [a for a in areas if rooms_of[a]]
    tree: dict[str, Any] = {}
    if size.levels >= 4:
        n = max(1, min(size.wings, len(areas)))
        wing_names = [style.wings[k] for k in rng.permutation(len(style.wings))][:n]
        for k, area in enumerate(areas):
            wing = wing_names[k * n // len(areas)]
            tree.setdefault(wing, {})[area] = {r: {} for r in rooms_of[area]}
        for hall in layout.halls:
            area = layout.area_of_block[hall.block]
            wing = next((w for w, sub in tree.items() if area in sub), wing_names[0])
            tree[wing][hall.name] = {}
    else:
        tree = {a: {r: {} for r in rooms_of[a]} for a in areas}
        for hall in layout.halls:
            tree[hall.name] = {}
    return {style.building: tree}


def _hierarchy_xml(nested: dict[str, Any]) -> str:
    lines = ['<?xml version="1.0" ?>', "<hierarchy>"]

    def walk(node: dict[str, Any], depth: int) -> None:
        for name, kids in node.items():
            pad = "  " * depth
            if kids:
                lines.append(f"{pad}<place name={quoteattr(name)}>")
                walk(kids, depth + 1)
                lines.append(f"{pad}</place>")
            else:
                lines.append(f"{pad}<place name={quoteattr(name)}/>")

    walk(nested, 1)
    lines.append("</hierarchy>")
    return "\n".join(lines) + "\n"


# -- goals -----------------------------------------------------------------------------------------------

def _redoor(layout: Layout, room: Room, edge: tuple, rng: np.random.Generator) -> bool:
    """Give ``room`` its door onto corridor segment ``edge`` if it borders it."""
    for side, e in block_sides(room.block).items():
        line = layout.corridor_sides[room.block].get(side)
        if e != edge or room.hall is not None or line is None:
            continue
        seg = _shared(room.rect, line)
        if seg is None:
            continue
        normal = {"left": (-1.0, 0.0), "right": (1.0, 0.0), "bottom": (0.0, -1.0), "top": (0.0, 1.0)}[side]
        room.door = _opening(seg, normal, DOOR_M, room.name, rng)
        room.via, room.edge = None, edge
        for other in layout.rooms:  # rooms reached through this one now open onto the same corridor
            if other.via == room.name:
                other.edge = edge
        return True
    return False


def _choose_goals(layout: Layout, rng: np.random.Generator) -> dict[str, str]:
    g = layout.graph
    bridges = {tuple(sorted(e)) for e in nx.bridges(g)}
    outer = min(layout.entrance)
    dead_nodes = {n for n in g.nodes if g.degree(n) == 1 and n != outer}
    dead_edges = {tuple(sorted(e)) for n in dead_nodes for e in g.edges(n)}
    start = np.array(layout.start[:2])

    def dist(r: Room) -> float:
        x0, y0, x1, y1 = r.rect
        return float(np.hypot((x0 + x1) / 2 - start[0], (y0 + y1) / 2 - start[1]))

    rooms = sorted(layout.rooms, key=lambda r: r.name)
    chosen: dict[str, str] = {}
    used_areas: set[str] = set()

    def pick(pool: list[Room], role: str) -> None:
        pool = [r for r in pool if r.name not in chosen and dist(r) > 6.0]
        fresh = [r for r in pool if r.area not in used_areas] or pool
        if not fresh:
            return
        fresh.sort(key=dist, reverse=True)
        top = fresh[: max(1, len(fresh) // 2)]
        room = top[int(rng.integers(len(top)))]
        chosen[room.name] = role
        used_areas.add(room.area)

    def on(edge_set: set, negate: bool = False) -> list[Room]:
        return [r for r in rooms if r.edge is not None and r.edge != layout.entrance
                and ((tuple(sorted(r.edge)) in edge_set) != negate)]

    pick(on(bridges, negate=True), "loop")
    if not on(dead_edges):
        for edge in sorted(dead_edges):
            for room in [rooms[k] for k in rng.permutation(len(rooms))]:
                if room.name not in chosen and _redoor(layout, room, edge, rng):
                    break
            if on(dead_edges):
                break
    pick(on(dead_edges), "dead end")
    pick([r for r in rooms if r.via is not None], "no arrow")
    if "no arrow" not in chosen.values():
        pick(rooms, "no arrow")
    pick([r for r in rooms if r.hall is not None], "hall")
    pick([r for r in rooms if r.via is not None], "through room")
    while len(chosen) < N_GOALS:
        before = len(chosen)
        pick(rooms, "far")
        if len(chosen) == before:
            break
    return chosen


# -- assembly ----------------------------------------------------------------------------------------------

def _png(image: np.ndarray) -> bytes:
    from PIL import Image

    buffer = io.BytesIO()
    Image.fromarray(image).save(buffer, format="PNG", optimize=False)
    return buffer.getvalue()


def generate(seed: int, *, style: str = "office", size: str = "medium", signage: str = "complete",
             arrows: str = DEFAULT_ARROWS) -> GeneratedWorld:
    """A building from ``seed`` (module docstring); pure: no files, same arguments, same bytes."""
    style_spec: Style = lookup(STYLES, style, "style")
    reading = lookup(ARROW_READINGS, arrows, "arrow reading")
    size_spec: Size = lookup(SIZES, size, "size")
    level = lookup(SIGNAGE, signage, "signage level")
    if not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    rng = np.random.default_rng([int(seed), 13])  # the layout depends on the seed only, not the signage
    layout = build_layout(style_spec, size_spec, rng)
    goal_roles = _choose_goals(layout, rng)
    nested = _hierarchy(style_spec, size_spec, layout, rng)
    hierarchy = Hierarchy.from_nested(nested)
    image = layout.raster()
    plan = Floorplan(image < 128, RESOLUTION_M, (0.0, 0.0))
    params = TruthParams()
    routes = Routes(plan, params)

    ids = [int(i) for i in rng.permutation(N_TAG_IDS)]
    tags: dict[int, Tag] = {}
    for opening in [r.door for r in layout.rooms if r.door] + [e for h in layout.halls for e in h.exits]:
        x, y, theta = opening.label_pose()
        tag_id = ids.pop(0)
        tags[tag_id] = Tag(tag_id, round(x, 4), round(y, 4), theta, "label", opening.place)

    hung = {k: hang(plan, t)[0] for k, t in tags.items()}  # where the check (and the scene) hang them
    facts = Facts(place_positions(hierarchy, hung, params.behind_m), hierarchy, params)
    world0 = _world(world_name(seed, style, size, signage, arrows), plan, tags, layout, goal_roles)
    oracle = oracle_paths(world0, sorted(goal_roles), params=params.oracle)

    # signage: which names each sign carries (seeded apart from the layout so levels share the building)
    srng = np.random.default_rng([int(seed), 13, 1])
    area_of = {r.name: r.area for r in layout.rooms}
    goals = sorted(goal_roles)
    area_only = {g for g in goals if goal_roles[g] == "no arrow"}
    others = [g for g in goals if g not in area_only]
    n_area_only = round(level.area_only_fraction * len(others))
    area_only |= {others[k] for k in srng.permutation(len(others))[:n_area_only]}
    spots = sign_spots(layout, plan, routes, list(tags.values()))
    entrance, junctions = spots[:1] if spots and spots[0].node is None else [], [s for s in spots if s.node is not None]
    if level.drop_fraction > 0:
        drop = set(srng.permutation(len(junctions))[: round(level.drop_fraction * len(junctions))].tolist())
        junctions = [s for k, s in enumerate(junctions) if k not in drop]
    writer = Writer(facts, routes, plan, hung, srng, reading)
    extras_pool = sorted({r.area for r in layout.rooms} | {h.name for h in layout.halls}
                         | {w for w in hierarchy.places if hierarchy.levels()[w] == 3}
                         | {r.name for r in layout.rooms if r.name not in area_only})
    extras_pool = [n for n in extras_pool if n not in area_only and n not in hierarchy.roots()]
    signs: list[Sign] = []
    for first in entrance + junctions:
        wanted = list(dict.fromkeys(area_of[g] if g in area_only else g for g in goals
                                    if first.node is None or _passes(oracle[g].path, layout, first.node)))
        best: tuple[int, Sign] | None = None
        for spot in [first, *first.alternates]:  # another wall of the junction when a goal cannot be pointed at
            sign = Sign(spot)
            for name in writer.arrows(sign, wanted):  # the goal itself when its area cannot be pointed at
                goal = next((g for g in goals if area_of[g] == name and g not in area_only), None)
                if goal is not None:
                    writer.arrows(sign, [goal])
            named = sum(1 for g in goals if (area_of[g] if g in area_only else g) in wanted
                        and ({g, area_of[g]} & sign.names()))
            if best is None or named > best[0]:
                best = (named, sign)
            if named == sum(1 for g in goals if (area_of[g] if g in area_only else g) in wanted):
                break
        assert best is not None
        sign = best[1]
        spot = sign.spot
        here = np.array([spot.x, spot.y])
        pool = [n for n in extras_pool if n not in sign.names()]
        pool.sort(key=lambda n: float(np.hypot(*(facts.positions[n] - here))) if n in facts.positions else 1e9)
        pool = pool[:12]
        picks = [pool[k] for k in srng.permutation(len(pool))][:EXTRA_NAMES + 2]
        for name in picks:
            if sum(len(v) for v in sign.arrows.values()) >= len(wanted) + EXTRA_NAMES:
                break
            writer.arrows(sign, [name])
        signs.append(sign)

    for sign in signs:
        tag_id = ids.pop(0)
        anchor = f"#{tag_id}"
        placed = _sign_tag(sign.spot, plan)
        facts.positions[anchor] = np.array([placed.x, placed.y])
        facts.facing[anchor] = sign.spot.theta
        writer.phrases(sign, anchor, 2)
        line = writer.in_line(sign)
        if line:
            sign.phrases.append(line)
        tags[tag_id] = Tag(tag_id, round(sign.spot.x, 4), round(sign.spot.y, 4), sign.spot.theta, "sign", "")
        sign.tag_id = tag_id

    misleading = _mislead(signs, level.wrong_fraction, srng)
    for sign in signs:
        tid = sign.tag_id
        tags[tid] = Tag(tid, tags[tid].x, tags[tid].y, tags[tid].theta, "sign", sign.text())
    signs_empty = [s for s in signs if not s.text()]
    for sign in signs_empty:  # a sign with nothing true to say is not hung
        del tags[sign.tag_id]
    misleading = [m for m in misleading if m["tag"] in tags]

    name = world_name(seed, style, size, signage, arrows)
    goal_tags = {g: next(t.id for t in tags.values() if t.kind == "label" and t.text == g) for g in goals}
    meta = {
        "format": FORMAT,
        "name": name,
        "title": f"{style_spec.building} ({style}, {size}, {signage} signage"
                 f"{'' if arrows == DEFAULT_ARROWS else f', {arrows} arrows'}, seed {seed})",
        "floorplan": {"image": "floorplan.png", "resolution_m": RESOLUTION_M, "origin_m": [0.0, 0.0],
                      "occupied_thresh": 0.65, "free_thresh": 0.2, "negate": False},
        "tags": "tags.json",
        "hierarchy": "hierarchy.xml",
        "start": {"x_m": layout.start[0], "y_m": layout.start[1], "heading_deg": math.degrees(layout.start[2])},
        "goals": goal_tags,
        "tag": {"size_m": 0.25, "height_m": 1.1},
        "walls": {"height_m": 2.0},
        "oracle_m": {g: round(oracle[g].length_m, 3) for g in goals},
        "generator": {"seed": int(seed), "style": style, "size": size, "signage": signage,
                      "goal_roles": goal_roles, "misleading": misleading},
    }
    if arrows != DEFAULT_ARROWS:  # written only when not the default, so every earlier world keeps its bytes
        meta["generator"]["arrows"] = arrows
    tag_list = [tags[k].to_dict() for k in sorted(tags)]
    for entry in tag_list:
        entry["theta_deg"] = round(entry["theta_deg"], 4)
    files = {
        "world.json": (json.dumps(meta, indent=2, sort_keys=True) + "\n").encode(),
        "floorplan.png": _png(image),
        "tags.json": (json.dumps({"name": name, "tags": tag_list}, indent=1, sort_keys=True) + "\n").encode(),
        "hierarchy.xml": _hierarchy_xml(nested).encode(),
    }
    final_tags = {t["id"]: Tag(t["id"], t["x_m"], t["y_m"], math.radians(t["theta_deg"]), t["kind"], t["text"])
                  for t in tag_list}
    world = _world(name, plan, final_tags, layout, goal_roles, goal_tags=goal_tags, oracle_m=meta["oracle_m"],
                   generator=meta["generator"], title=meta["title"])
    return GeneratedWorld(name, int(seed), style, size, signage, files, world, hierarchy, layout, goal_roles,
                          misleading, arrows)


def _passes(path: np.ndarray, layout: Layout, node: tuple[int, int]) -> bool:
    x, y = layout.node_xy(node)
    reach = max(layout.widths_x.get(node[0], 0.0), layout.widths_y.get(node[1], 0.0)) / 2 + 0.5
    return bool((np.abs(path[:, 0] - x) <= reach).__and__(np.abs(path[:, 1] - y) <= reach).any())


def _mislead(signs: list[Sign], fraction: float, rng: np.random.Generator) -> list[dict[str, Any]]:
    """Turn one arrow the wrong way on ``fraction`` of the signs (at least one when fraction > 0)."""
    if fraction <= 0:
        return []
    with_arrows = [s for s in signs if s.arrows]
    count = max(1, round(fraction * len(with_arrows))) if with_arrows else 0
    out = []
    for k in rng.permutation(len(with_arrows))[:count]:
        sign = with_arrows[int(k)]
        arrow = sorted(a for a, v in sign.arrows.items() if v)[0]
        name = sign.arrows[arrow].pop(0)
        if not sign.arrows[arrow]:
            del sign.arrows[arrow]
        true_dir = arrow_direction(sign.spot.theta, arrow)
        wrong = [a for a in ("LEFT", "RIGHT", "UP", "DOWN")
                 if abs(math.degrees(math.remainder(arrow_direction(sign.spot.theta, a) - true_dir, math.tau))) > 60]
        new = wrong[int(rng.integers(len(wrong)))]
        sign.arrows.setdefault(new, []).append(name)
        out.append({"tag": sign.tag_id, "name": name, "arrow": new})
    return out


def _world(name: str, plan: Floorplan, tags: dict[int, Tag], layout: Layout, goal_roles: dict[str, str], *,
           goal_tags: dict[str, int] | None = None, oracle_m: dict[str, float] | None = None,
           generator: dict[str, Any] | None = None, title: str | None = None) -> World:
    if goal_tags is None:
        goal_tags = {g: next(t.id for t in tags.values() if t.kind == "label" and t.text == g) for g in goal_roles}
    return World(name=name, root=Path("."), title=title or name, floorplan=plan, tags=dict(tags),
                 hierarchy_path=Path("hierarchy.xml"), start=layout.start, goals=goal_tags,
                 oracle_m=oracle_m, generator=generator)


# -- files -------------------------------------------------------------------------------------------------

def write_world(generated: GeneratedWorld, out_dir: Path) -> Path:
    """Write the world folder atomically (a temporary folder beside it, then a rename).

    An existing empty folder is replaced; an existing folder holding exactly
    these files (a previous generation with the same arguments) is left as it
    is; any other existing folder raises ``FileExistsError``.
    """
    out_dir = Path(out_dir)
    if out_dir.exists():
        if not out_dir.is_dir():
            raise FileExistsError(f"{out_dir} exists and is not a folder")
        present = sorted(p.name for p in out_dir.iterdir())
        if present:
            same = present == sorted(generated.files) and all(
                (out_dir / n).read_bytes() == b for n, b in generated.files.items())
            if same:
                return out_dir
            raise FileExistsError(f"{out_dir} exists and holds something else; remove it or choose another --out")
        out_dir.rmdir()
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.", dir=out_dir.parent))
    try:
        for name, content in generated.files.items():
            (tmp / name).write_bytes(content)
        os.replace(tmp, out_dir)
    except OSError:
        shutil.rmtree(tmp, ignore_errors=True)
        if out_dir.is_dir() and all((out_dir / n).is_file() and (out_dir / n).read_bytes() == b
                                    for n, b in generated.files.items()):
            return out_dir  # another process wrote the same generation first
        raise
    return out_dir


def generated_world(seed: int, *, style: str = "office", size: str = "medium", signage: str = "complete",
                    arrows: str = DEFAULT_ARROWS, root: Path) -> Path:
    """The folder ``root/<world_name>``, generated and written if not already there."""
    folder = Path(root) / world_name(seed, style, size, signage, arrows)
    if (folder / "world.json").is_file():
        return folder
    return write_world(generate(seed, style=style, size=size, signage=signage, arrows=arrows), folder)


__all__ = ["GeneratedWorld", "generate", "write_world", "generated_world", "world_name"]
