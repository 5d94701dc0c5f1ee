"""``scripts/placement_by_cue.py``: how far the abstract map places an unseen place, by how the cues name it."""

from __future__ import annotations

import re

import numpy as np

from abstract_map.hierarchy import Hierarchy
from sim.world.data import load_world
from tests.repo_files import load_file, refused_in_one_line


def load():
    return load_file("scripts/placement_by_cue.py", "placement_by_cue")


def test_on_the_zoo_a_named_place_is_placed_far_better_than_by_the_hierarchy_alone(capsys):
    """Every labelled place is held out once; those a phrase or an arrow names land within a few metres of their
    label, those only the hierarchy places about 15 m off (the zoo's areas are wide)."""
    script = load()
    world = load_world("zoo")
    misses = script.held_out_misses(world.tags.values(), Hierarchy.from_xml(world.hierarchy_path), world.start,
                                    np.random.default_rng(0))
    labelled = {t.text for t in world.tags.values() if t.kind == "label"}
    assert len(misses) == len(labelled)
    rms = {k: np.sqrt(np.mean([d ** 2 for kind, d in misses if kind == k])) for k in ("phrase", "arrow", "hierarchy")}
    assert rms["phrase"] < 6.0 and rms["arrow"] < 6.0 and rms["hierarchy"] > 2 * max(rms["phrase"], rms["arrow"])
    assert script.main(["--world", "zoo"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^zoo +hierarchy +places +\d+ +rms +[\d.]+ m", out, re.MULTILINE) and "spread a side" in out


def test_a_world_that_is_not_there_is_one_line_and_exit_2(capsys, tmp_path):
    assert "nowhere" in refused_in_one_line(load().main, ["--world", str(tmp_path / "nowhere")], capsys,
                                            "placement_by_cue")
