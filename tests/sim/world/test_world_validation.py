"""A world folder is validated completely at load (issue 9, item 4), with every problem listed at once."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from abstract_map.errors import AbstractMapError
from sim.world.data import WorldError, load_world
from tests.conftest import slow_property
from tests.json_edits import leaves, set_path


def edit(root: Path, name: str, change) -> Path:
    data = json.loads((root / name).read_text())
    change(data)
    (root / name).write_text(json.dumps(data, allow_nan=True))
    return root


def png(size: tuple[int, int]):
    def write(root: Path) -> None:
        from PIL import Image

        Image.fromarray(np.full(size, 255, dtype=np.uint8)).save(root / "floorplan.png")
    return write


CHAIN = "".join(f'<place name="L{i}">' for i in range(600)) + '<place name="A"/>' + "</place>" * 600

BAD = {
    "start abc": (lambda r: edit(r, "world.json", lambda d: d.update(start="abc")), "start"),
    "start missing x_m": (lambda r: edit(r, "world.json", lambda d: d["start"].pop("x_m")), "x_m"),
    "start in a wall": (lambda r: edit(r, "world.json", lambda d: d["start"].update(x_m=0.05)), "free floor"),
    "png 0 bytes": (lambda r: (r / "floorplan.png").write_bytes(b""), "not a readable image"),
    "png corrupt": (lambda r: (r / "floorplan.png").write_bytes(b"\x89PNG\r\n\x1a\njunk"), "not a readable image"),
    "png 1x1": (png((1, 1)), "1 x 1 pixels"),
    "tags []": (lambda r: edit(r, "world.json", lambda d: d.update(tags=[])), "tags"),
    "no tags": (lambda r: edit(r, "tags.json", lambda d: d.update(tags=[])), "non-empty list"),
    "goals null": (lambda r: edit(r, "world.json", lambda d: d.update(goals=None)), "goals"),
    "no goals": (lambda r: edit(r, "world.json", lambda d: d.update(goals={})), "goals"),
    "goal id 17.9": (lambda r: edit(r, "world.json", lambda d: d["goals"].update(A=17.9)), "17.9"),
    "negative resolution": (lambda r: edit(r, "world.json", lambda d: d["floorplan"].update(resolution_m=-0.05)),
                            "resolution_m"),
    "NaN threshold": (lambda r: edit(r, "world.json", lambda d: d["floorplan"].update(occupied_thresh=math.nan)),
                      "occupied_thresh"),
    "null tag text": (lambda r: edit(r, "tags.json", lambda d: d["tags"][1].update(text=None)), "text"),
    "goal not in the hierarchy": (lambda r: (r / "hierarchy.xml").write_text('<place name="B"/>'),
                                  "not a place of the hierarchy"),
    "sign past here": (lambda r: edit(r, "tags.json", lambda d: d["tags"][1].update(text="X is past here")),
                       "tag 1"),
    "label #start": (lambda r: edit(r, "tags.json", lambda d: d["tags"][0].update(text="#start")), "#start"),
    "tag id out of the family": (lambda r: edit(r, "tags.json", lambda d: d["tags"][3].update(id=9999)), "9999"),
    "image outside the folder": (lambda r: edit(r, "world.json", lambda d: d["floorplan"].update(image="../x.png")),
                                 "inside the world folder"),
    "deep tags.json": (lambda r: (r / "tags.json").write_text("[" * 100_000 + "]" * 100_000), "not valid JSON"),
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_issue9_item4_out_of_spec_worlds_are_refused_by_name(tmp_path, tiny_world_writer, name):
    change, message = BAD[name]
    change(tiny_world_writer(tmp_path / "w"))
    with pytest.raises(WorldError, match=message.replace("(", r"\(")) as raised:
        load_world(tmp_path / "w")
    assert "\n" not in str(raised.value)


def test_issue9_item4_every_problem_is_listed_at_once(tmp_path, tiny_world_writer):
    root = tiny_world_writer(tmp_path / "w")
    edit(root, "world.json", lambda d: (d["floorplan"].update(resolution_m=-1), d["start"].update(x_m="abc"),
                                        d["goals"].update(A=17.9)))
    edit(root, "tags.json", lambda d: d["tags"][1].update(text="X is near X"))
    with pytest.raises(WorldError) as raised:
        load_world(root)
    message = str(raised.value)
    for part in ("resolution_m", "start x_m", "17.9", "tag 1"):
        assert part in message


def test_issue9_item4_a_600_level_hierarchy_loads(tmp_path, tiny_world_writer):
    root = tiny_world_writer(tmp_path / "w")
    (root / "hierarchy.xml").write_text(f"<hierarchy>{CHAIN}</hierarchy>")
    world = load_world(root)
    assert world.goals == {"A": 0}






HOSTILE = st.one_of(st.none(), st.booleans(), st.floats(allow_nan=True, allow_infinity=True),
                    st.integers(-(10**400), 10**400), st.floats(-20, 20), st.text(max_size=12), st.just([]),
                    st.just({}), st.lists(st.floats(-20, 20), max_size=3),
                    st.sampled_from(["$UP$ A", "A is past here", "#start", "A is in A", "floorplan.png", "label"]))


@pytest.fixture(scope="module")
def template(tmp_path_factory, tiny_world_writer):
    root = tiny_world_writer(tmp_path_factory.mktemp("template") / "w")
    return json.loads((root / "world.json").read_text()), json.loads((root / "tags.json").read_text())


@slow_property()
@given(which=st.sampled_from(["world.json", "tags.json"]), index=st.integers(0, 10_000), value=HOSTILE)
def test_any_world_folder_loads_and_works_or_is_refused(tmp_path_factory, tiny_world_writer, template, which, index,
                                                         value):
    meta, tags = template
    spots = leaves(meta if which == "world.json" else tags)
    path = spots[index % len(spots)]
    if which == "world.json":
        meta = set_path(meta, path, value)
    else:
        tags = set_path(tags, path, value)
    root = tiny_world_writer(tmp_path_factory.mktemp("world") / "w")
    (root / "world.json").write_text(json.dumps(meta, allow_nan=True))
    (root / "tags.json").write_text(json.dumps(tags, allow_nan=True))
    try:
        world = load_world(root)
    except AbstractMapError as exc:
        assert isinstance(exc, WorldError) and "\n" not in str(exc)
        return
    # what a trial does first must work: the hierarchy, every tag read, every goal set, a settle
    from abstract_map.hierarchy import Hierarchy
    from abstract_map.model import AbstractMap

    model = AbstractMap.from_hierarchy(Hierarchy.from_xml(world.hierarchy_path), world.start)
    for tag in world.tags.values():
        if tag.kind != "empty":
            model.observe_tag(tag.id, tag.text, (tag.x, tag.y, tag.theta), kind=tag.kind)
    for goal, tag_id in world.goals.items():
        model.set_goal(goal)
        assert world.tags[tag_id].text == goal
    model.settle()
    assert all(np.all(np.isfinite(xy)) for xy in model.positions.values())
    assert world.floorplan.resolution > 0 and np.all(np.isfinite(world.floorplan.extent))
