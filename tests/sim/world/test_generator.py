"""The building generator: determinism, the format, the goals' spread, and that its worlds pass the check."""

from __future__ import annotations

import functools
import hashlib
import math
import os
import subprocess
import sys

import networkx as nx
import numpy as np
import pytest

from abstract_map.clauses import Locational, Relational
from abstract_map.grammar import Anchor, parse_cue
from abstract_map.hierarchy import Hierarchy
from abstract_map.prepositions import PREPOSITIONS
from sim.world.data import Floorplan, load_world
from sim.world.generator import generate, generated_world, world_name, write_world
from sim.world.oracle import OracleParams, free_cells
from sim.world.styles import SIGNAGE, SIZES, STYLES

STYLE_CASES = [(style, size, seed) for style in STYLES for size, seed in (("small", 1), ("medium", 1000))]


@functools.cache
def made(seed: int, style: str = "office", size: str = "small", signage: str = "complete"):
    return generate(seed, style=style, size=size, signage=signage)


@functools.cache
def checked(seed: int, style: str = "office", size: str = "small", signage: str = "complete"):
    return made(seed, style, size, signage).check()


def arrows_and_phrases(world):
    for tag in world.tags.values():
        if tag.kind == "sign":
            for clause in parse_cue(tag.text, Anchor(f"#{tag.id}", tag.x, tag.y, tag.theta), kind="sign"):
                yield tag, clause


def test_same_seed_same_bytes_and_names_are_unique():
    a = generate(5, style="hospital", size="small")
    b = generate(5, style="hospital", size="small")
    assert a.files == b.files
    assert generate(6, style="hospital", size="small").files["floorplan.png"] != a.files["floorplan.png"]
    names = {world_name(s, st, sz, sg) for s in (1, 2) for st in STYLES for sz in SIZES for sg in SIGNAGE}
    assert len(names) == 2 * len(STYLES) * len(SIZES) * len(SIGNAGE)
    assert b'"name": "gen-hospital-small-complete-5"' in a.files["world.json"]


def test_same_bytes_in_another_process_with_another_hash_seed():
    script = ("import hashlib, sys; from sim.world.generator import generate; "
              "g = generate(7, style='campus', size='small', signage='misleading'); "
              "sys.stdout.write(hashlib.sha256(b''.join(g.files[k] for k in sorted(g.files))).hexdigest())")
    digests = {subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True,
                              env={**os.environ, "PYTHONHASHSEED": seed}).stdout for seed in ("1", "2")}
    here = made(7, "campus", "small", "misleading")
    assert digests == {hashlib.sha256(b"".join(here.files[k] for k in sorted(here.files))).hexdigest()}


@pytest.mark.parametrize("style, size, seed", STYLE_CASES)
def test_every_style_makes_a_world_that_passes_the_check(style, size, seed, tmp_path):
    g = made(seed, style, size)
    report = checked(seed, style, size)
    assert report.ok, report.table()
    assert report.checked["arrows"] >= 5 and report.checked["phrases"] >= 5
    folder = write_world(g, tmp_path / g.name)
    world = load_world(folder)
    hierarchy = Hierarchy.from_xml(world.hierarchy_path)
    assert set(world.goals) == set(g.goal_roles) and len(world.goals) == 5
    assert set(world.oracle_m) == set(world.goals) and all(v > 0 for v in world.oracle_m.values())
    assert all(0 <= t <= 586 for t in world.tags)
    assert 2 <= max(hierarchy.levels().values()) <= 4
    for tag in world.tags.values():  # every text parses; labels name places of the hierarchy
        parse_cue(tag.text, Anchor(f"#{tag.id}", tag.x, tag.y, tag.theta), kind=tag.kind)
        assert tag.kind != "label" or tag.text in hierarchy.places
    for place in hierarchy.places:  # names the grammar keeps whole
        assert "," not in place and " and " not in place and " is " not in place
        assert not place.lower().startswith(("the ", "a ", "an "))
    if size == "medium":
        rooms = len(g.layout.rooms)
        assert 40 <= g.layout.width <= 70 and 15 <= rooms <= 48 and 25 <= len(world.tags) <= 60


def test_goals_are_spread_behind_a_loop_off_a_dead_end_and_named_by_no_arrow():
    for style in STYLES:
        g = made(1000, style, "medium")
        roles = {role: goal for goal, role in g.goal_roles.items()}
        assert {"loop", "dead end", "no arrow"} <= set(roles)
        rooms = {r.name: r for r in g.layout.rooms}
        graph = g.layout.graph
        bridges = {tuple(sorted(e)) for e in nx.bridges(graph)}
        assert tuple(sorted(rooms[roles["loop"]].edge)) not in bridges  # its corridor lies on a cycle
        dead = rooms[roles["dead end"]].edge
        outer = min(g.layout.entrance)
        assert any(graph.degree(n) == 1 and n != outer for n in dead)
        named = {c.toponym for _, c in arrows_and_phrases(g.world) if isinstance(c, Locational) and c.kind == "arrow"}
        assert roles["no arrow"] not in named


def test_every_preposition_row_is_written_and_true():
    rows = set()
    for style in STYLES:
        g = made(1000, style, "medium")
        for _, clause in arrows_and_phrases(g.world):
            if isinstance(clause, Relational):
                rows.add(next(r.words[0] for r in PREPOSITIONS if clause.preposition in r.words))
        assert not [f for f in checked(1000, style, "medium").failures if f.kind in ("arrow", "phrase")]
    assert rows == {r.words[0] for r in PREPOSITIONS}


def test_signage_levels_share_the_building():
    complete, sparse, misleading = (made(3, "office", "medium", s) for s in ("complete", "sparse", "misleading"))
    assert complete.files["floorplan.png"] == sparse.files["floorplan.png"] == misleading.files["floorplan.png"]
    n_signs = [sum(t.kind == "sign" for t in g.world.tags.values()) for g in (complete, sparse, misleading)]
    assert n_signs[1] < n_signs[0] and n_signs[2] == n_signs[1]
    assert misleading.misleading and not complete.misleading
    report = checked(3, "office", "medium", "misleading")
    declared = [f for f in report.findings if f.declared]
    assert report.ok and {(int(f.subject.split()[1])) for f in declared} == {m["tag"] for m in misleading.misleading}


def arrow_offsets_deg(g) -> list[float]:
    """Per arrow, degrees between its direction and the bearing from its sign to the nearest label of its place."""
    from sim.world.truth import angle_between, place_tags

    out = []
    for tag, clause in arrows_and_phrases(g.world):
        if isinstance(clause, Locational) and clause.kind == "arrow":
            label = min(place_tags(clause.toponym, g.hierarchy, g.world.tags),
                        key=lambda t: math.hypot(t.x - tag.x, t.y - tag.y))
            arrow = np.array([math.cos(clause.direction), math.sin(clause.direction)])
            out.append(angle_between(arrow, np.array([label.x - tag.x, label.y - tag.y])))
    return out


def test_the_park_is_open_ground_and_its_arrows_point_nearer_their_places():
    """The park keeps every path, so each block of rooms is an island in open ground, and from there an
    arrow's place lies within 45 degrees of it more often than in an office (development seeds 0-11 measured
    70 % against 53 %; the zoo's signs 96 %)."""
    within = {}
    for style in ("park", "office"):
        offsets = [o for seed in range(4) for o in arrow_offsets_deg(made(seed, style, "medium"))]
        within[style] = float(np.mean(np.array(offsets) <= 45.0))
    assert within["park"] > within["office"] + 0.1
    park, office = made(0, "park", "medium"), made(0, "office", "medium")
    cx, cy = len(park.layout.xs) - 1, len(park.layout.ys) - 1  # blocks across and up
    assert park.layout.graph.number_of_edges() == (cx - 1) * cy + (cy - 1) * cx  # no path cut
    assert not park.layout.halls and (park.layout.raster() > 0).mean() > (office.layout.raster() > 0).mean()


def test_fingerposts_point_at_their_places_in_the_same_building_and_pass_their_own_check():
    """``arrows="bearing"``: every arrow within 45 degrees of the bearing from its reader to its place, where
    wayfinding arrows in the same office point the way and so miss their places far more often; the plan, the
    labels and the goals are the way-signed building's, the world says which reading it was written by, and
    the default's bytes carry no word of it."""
    from sim.world.truth import DEFAULT_ARROWS

    way, posts = made(2, "office", "medium"), generate(2, style="office", size="medium", arrows="bearing")
    assert posts.files["floorplan.png"] == way.files["floorplan.png"] and posts.world.goals == way.world.goals
    assert posts.name == "gen-office-medium-complete-bearing-2" and posts.arrows == "bearing"
    assert posts.world.generator["arrows"] == "bearing" and b'"arrows"' not in way.files["world.json"]
    assert way.arrows == DEFAULT_ARROWS and world_name(2, "office", "medium", "complete") == way.name
    report = posts.check()
    assert report.ok and report.checked["arrows"] > 0
    within = {name: float(np.mean(np.array(arrow_offsets_deg(g)) <= 45.0)) for name, g in (("way", way),
                                                                                            ("posts", posts))}
    assert within["posts"] > 0.9 > within["way"] + 0.2
    with pytest.raises(ValueError, match="arrow reading 'crow'"):
        generate(2, style="office", size="small", arrows="crow")


def test_wide_paths_leave_a_block_and_a_sign_with_few_places_near_it_skips_between():
    """Small parks once drew paths wider than their lattice cells (seeds 2 and 3 crashed), and a sign with only
    two places near it once asked for a "between" of three (medium park seed 14 crashed)."""
    from sim.world.layout import MIN_BLOCK_M
    from sim.world.styles import SIZES

    for seed in (2, 3):
        g = made(seed, "park", "small")
        widest = max([*g.layout.widths_x.values(), *g.layout.widths_y.values()])
        assert widest <= SIZES["small"].cell_m[0] - MIN_BLOCK_M + 1e-9 and checked(seed, "park", "small").ok
    assert checked(14, "park", "medium").ok


def test_every_junction_sign_is_read_from_its_junction():
    """A junction's sign hangs where the junction's centre sees its reader, never in a room behind its wall
    (office seed 3 once hung one south of a T's crossing wall, read only from the room below)."""
    from sim.world.signage import in_sight
    from sim.world.truth import Routes, TruthParams

    for style in ("office", "museum"):
        g = made(3, style, "medium")
        layout, plan = g.layout, g.world.floorplan
        routes = Routes(plan, TruthParams())
        junctions = [layout.node_xy(n) for n in layout.graph.nodes if layout.graph.degree(n) >= 3]
        start = np.array(g.world.start[:2])
        for tag in g.world.tags.values():
            if tag.kind != "sign" or math.dist((tag.x, tag.y), start) < 6.0:  # the entrance's sign
                continue
            pose = routes.reading_pose(tag)
            assert pose is not None and any(math.dist(j, pose) < 6.0 and in_sight(plan, j, pose)
                                            for j in junctions), f"{style}: sign {tag.id} hidden from its junction"


def test_one_metre_doors_pass_the_oracles_inflation():
    for cell in (0.05, 0.1):
        occupied = np.ones((60, 60), dtype=bool)
        occupied[10:50, 5:28] = occupied[10:50, 32:55] = False  # two rooms, 0.2 m wall between (at 0.05 m/px)
        occupied[25:45, 28:32] = False  # a 1 m door (20 px) through it
        plan = Floorplan(occupied, 0.05, (0.0, 0.0))
        from sim.world.oracle import distance_field, pool_plan

        grid = pool_plan(plan, cell)
        free = free_cells(grid, OracleParams().robot_radius_m)
        a, b = grid.world_to_pixel(np.array([[0.7, 1.5], [2.3, 1.5]]))
        cumulative, _ = distance_field(free, [tuple(a)])
        assert math.isfinite(cumulative[tuple(b)])


def test_write_world_is_atomic_and_refuses_to_overwrite(tmp_path):
    g = made(2)
    folder = write_world(g, tmp_path / "w")
    assert sorted(p.name for p in folder.iterdir()) == sorted(g.files)
    assert write_world(g, folder) == folder  # the same generation: left as it is
    with pytest.raises(FileExistsError):
        write_world(made(1), folder)
    (tmp_path / "empty").mkdir()
    assert write_world(g, tmp_path / "empty").is_dir()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary folder left behind
    path = generated_world(2, style="office", size="small", root=tmp_path / "root")
    assert path.name == "gen-office-small-complete-2" and (path / "world.json").read_bytes() == g.files["world.json"]
    assert generated_world(2, style="office", size="small", root=tmp_path / "root") == path


def test_bad_arguments_are_value_errors():
    for kwargs in ({"style": "castle"}, {"size": "huge"}, {"signage": "none"}):
        with pytest.raises(ValueError, match="known"):
            generate(1, **kwargs)
    with pytest.raises(ValueError, match="seed"):
        generate(-1)
