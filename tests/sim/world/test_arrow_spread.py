"""``scripts/arrow_spread.py``: where a label named by an arrow hangs, in the arrow's frame."""

from __future__ import annotations

import math

import pytest

from sim.world.data import Tag, load_world
from tests.repo_files import load_file, refused_in_one_line


def load():
    return load_file("scripts/arrow_spread.py", "arrow_spread")


def test_a_label_is_measured_along_and_across_its_arrow():
    """A sign facing south (its reader stands south of it), whose UP arrow points north through the sign: a
    label 6 m north and 2 m west of it lies 6 m along the arrow and 2 m to its left. A place with no label and
    a label no arrow names are left out."""
    script = load()
    tags = [Tag(1, 0.0, 0.0, -math.pi / 2, "sign", "$UP$ Lab, Nowhere\n$LEFT$ Store"),
            Tag(2, -2.0, 6.0, 0.0, "label", "lab"),
            Tag(3, 9.0, 9.0, 0.0, "label", "Office")]
    (along, across), = script.arrow_offsets(tags)
    assert along == pytest.approx(6.0) and across == pytest.approx(2.0)


def test_the_zoo_arrows_place_their_labels_to_a_few_metres(capsys):
    script = load()
    assert script.main(["--world", "zoo"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("zoo") and "miss of a place 8 m along" in out
    along = sorted(a for a, _ in script.world_offsets(load_world("zoo")))
    assert len(along) > 15 and 5.0 < along[len(along) // 2] < 9.0


def test_a_world_that_is_not_there_is_one_line_and_exit_2(capsys, tmp_path):
    assert "nowhere" in refused_in_one_line(load().main, ["--world", str(tmp_path / "nowhere")], capsys, "arrow_spread")
