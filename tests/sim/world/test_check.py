"""The world check: broken worlds fail with a line naming what is wrong; the command's exit codes; the zoo."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from abstract_map import cli
from abstract_map.clauses import Locational
from abstract_map.grammar import Anchor, parse_cue
from sim.world.check import check_world
from sim.world.data import load_world
from sim.world.generator import generate, write_world
from sim.world.truth import Facts, TruthParams, phrase_verdict, place_positions

ZOO = Path(__file__).resolve().parents[3] / "worlds" / "zoo"
SEED = 11
OPPOSITE = {"LEFT": "RIGHT", "RIGHT": "LEFT", "UP": "DOWN", "DOWN": "UP"}


@pytest.fixture(scope="module")
def generated():
    return generate(SEED, style="office", size="small")


@pytest.fixture
def folder(generated, tmp_path):
    return write_world(generated, tmp_path / generated.name)


def edit_tags(folder: Path, change) -> None:
    path = folder / "tags.json"
    data = json.loads(path.read_text())
    change(data["tags"])
    path.write_text(json.dumps(data))


def paint(folder: Path, x0: float, y0: float, x1: float, y1: float, value: int) -> None:
    """Set the floor plan to ``value`` (0 wall, 255 free) over a rectangle in metres (origin 0, 0.05 m/px)."""
    image = np.array(Image.open(folder / "floorplan.png"))
    rows = image.shape[0]
    image[rows - round(y1 / 0.05):rows - round(y0 / 0.05), round(x0 / 0.05):round(x1 / 0.05)] = value
    Image.fromarray(image).save(folder / "floorplan.png")


def failing(folder: Path) -> list:
    return check_world(load_world(folder)).failures


def test_the_generated_world_passes(folder):
    assert check_world(load_world(folder)).ok


def test_a_tag_inside_a_wall_fails(generated, folder):
    tag = next(t for t in generated.world.tags.values() if t.kind == "label")
    paint(folder, tag.x - 0.6, tag.y - 0.6, tag.x + 0.6, tag.y + 0.6, 0)
    found = [f for f in failing(folder) if f.subject == f"tag {tag.id}"]
    assert any(f.kind == "wall" and "inside a wall" in f.message for f in found)
    assert any(f.kind == "unreadable" for f in found)


def test_an_unreachable_goal_fails(generated, folder):
    # wall the goal's label off in a sealed box built in front of it
    goal, tag_id = sorted(generated.world.goals.items())[0]
    tag = generated.world.tags[tag_id]
    n = np.array([math.cos(tag.theta), math.sin(tag.theta)])
    t = np.array([-n[1], n[0]])
    p = np.array([tag.x, tag.y])
    lo, hi = np.minimum(p - 1.0 * t, p + 1.4 * n + 1.0 * t), np.maximum(p - 1.0 * t, p + 1.4 * n + 1.0 * t)
    paint(folder, *lo, *hi, 0)  # a solid block in front of the label ...
    inner_lo = np.minimum(p - 0.8 * t, p + 1.2 * n + 0.8 * t)
    inner_hi = np.maximum(p - 0.8 * t, p + 1.2 * n + 0.8 * t)
    paint(folder, *inner_lo, *inner_hi, 255)  # ... hollowed into a sealed room that only the label faces
    found = failing(folder)
    assert any(f.kind == "goal" and f.subject == f"goal {goal}" and "unreachable" in f.message for f in found)


def test_a_wrong_arrow_fails(generated, folder):
    sign = next(t for t in generated.world.tags.values() if t.kind == "sign" and "$" in t.text)
    line = next(li for li in sign.text.split("\n") if li.startswith("$"))
    arrow = line[1:line.index("$", 1)]
    wrong = line.replace(f"${arrow}$", f"${OPPOSITE[arrow]}$", 1)
    edit_tags(folder, lambda tags: [t.update(text=t["text"].replace(line, wrong)) for t in tags if t["id"] == sign.id])
    found = [f for f in failing(folder) if f.kind == "arrow"]
    assert found and all(f.subject == f"tag {sign.id}" for f in found)
    assert f"${OPPOSITE[arrow]}$" in found[0].message and "deg off" in found[0].message


def test_a_false_phrase_fails(generated, folder):
    world = generated.world
    sign = next(t for t in world.tags.values() if t.kind == "sign")
    facts = Facts(place_positions(generated.hierarchy, world.tags, TruthParams().behind_m), generated.hierarchy)
    facts.positions[f"#{sign.id}"] = np.array([sign.x, sign.y])
    rooms = sorted(r.name for r in generated.layout.rooms)
    false = next((a, b) for a in rooms for b in rooms
                 if a != b and phrase_verdict(facts, "past", a, (b,), f"#{sign.id}") is not None)
    text = sign.text + f"\nThe {false[0]} is past the {false[1]}"
    edit_tags(folder, lambda tags: [t.update(text=text) for t in tags if t["id"] == sign.id])
    found = [f for f in failing(folder) if f.kind == "phrase"]
    assert len(found) == 1 and found[0].subject == f"tag {sign.id}" and false[0] in found[0].message


def test_fingerposts_are_checked_by_the_bearing_their_world_declares(tmp_path):
    """A world generated with bearing arrows passes its own check; read as wayfinding signs (its declaration
    removed) some of its arrows fail against their routes' first legs, and an unknown declaration is a finding
    naming it."""
    posts = write_world(generate(SEED, style="office", size="small", arrows="bearing"), tmp_path / "posts")
    assert check_world(load_world(posts)).ok
    meta = json.loads((posts / "world.json").read_text())
    for value, expect in ((None, "first leg"), ("crow", "generator.arrows 'crow'")):
        if value is None:
            del meta["generator"]["arrows"]
        else:
            meta["generator"]["arrows"] = value
        (posts / "world.json").write_text(json.dumps(meta))
        found = [f for f in failing(posts) if f.kind == "arrow"]
        assert found and any(expect in f.message for f in found), value


def test_every_arrow_is_checked_against_its_route(generated):
    report = check_world(generated.world, hierarchy=generated.hierarchy)
    arrows = sum(isinstance(c, Locational) and c.kind == "arrow"
                 for t in generated.world.tags.values() if t.kind == "sign"
                 for c in parse_cue(t.text, Anchor(f"#{t.id}", t.x, t.y, t.theta), kind="sign"))
    assert report.checked["arrows"] == arrows > 0 and report.ok


def test_a_stale_oracle_fails_and_write_oracle_fixes_it(folder, capsys):
    meta = json.loads((folder / "world.json").read_text())
    goal = sorted(meta["oracle_m"])[0]
    meta["oracle_m"][goal] += 5.0
    (folder / "world.json").write_text(json.dumps(meta))
    assert [f.subject for f in failing(folder) if f.kind == "oracle"] == [f"goal {goal}"]
    assert cli.main(["world", "check", str(folder), "--write-oracle"]) == 0
    assert not failing(folder)


def test_command_exit_codes(generated, folder, tmp_path, capsys):
    assert cli.main(["world", "check", str(folder)]) == 0
    assert "OK: nothing fails" in capsys.readouterr().out
    broken = tmp_path / "broken"
    shutil.copytree(folder, broken)
    goal = next(iter(json.loads((folder / "world.json").read_text())["oracle_m"]))
    meta = json.loads((broken / "world.json").read_text())
    meta["oracle_m"][goal] += 5.0  # a stale oracle: a finding, exit 1
    (broken / "world.json").write_text(json.dumps(meta))
    assert cli.main(["world", "check", str(broken)]) == 1
    assert f"goal {goal}" in capsys.readouterr().out
    paint(broken, 0, 0, 100, 100, 0)  # everything wall: the start is refused at load, one line, exit 2
    assert cli.main(["world", "check", str(broken)]) == 2
    assert "start" in capsys.readouterr().err
    assert cli.main(["world", "check", str(tmp_path / "nowhere")]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1
    out = tmp_path / "new"
    assert cli.main(["world", "generate", "--seed", str(SEED), "--size", "small", "--out", str(out)]) == 0
    assert (out / "world.json").read_bytes() == generated.files["world.json"]
    posts = tmp_path / "posts"
    assert cli.main(["world", "generate", "--seed", str(SEED), "--size", "small", "--arrows", "bearing",
                     "--out", str(posts)]) == 0
    assert json.loads((posts / "world.json").read_text())["generator"]["arrows"] == "bearing"
    assert cli.main(["world", "check", str(posts)]) == 0
    for bad in (["--seed", "x"], ["--seed", "1", "--style", "castle"], ["--seed", "1", "--size", "huge"],
                ["--seed", "1", "--arrows", "crow"],
                ["--seed", "2", "--size", "small"]):  # the last: out holds another world
        capsys.readouterr()
        assert cli.main(["world", "generate", *bad, "--out", str(out)]) == 2
        assert len(capsys.readouterr().err.strip().splitlines()) == 1


def test_the_zoo_signs_fail_as_the_readme_says():
    report = check_world(load_world(ZOO))
    found = {(f.kind, f.subject) for f in report.failures}
    assert found == {
        ("wall", "tag 1"), ("wall", "tag 14"), ("wall", "tag 30"),  # drawn free-standing
        ("arrow", "tag 3"), ("arrow", "tag 29"),
        ("phrase", "tag 8"), ("phrase", "tag 15"), ("phrase", "tag 21"),
    }, report.table()
    assert set(report.oracle_m) == set(load_world(ZOO).goals)
