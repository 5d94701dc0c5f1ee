"""``scripts/fingerpost_marks.py``: how often a sign carries the fingerpost test's mark, on true plans."""

from __future__ import annotations

import re

from sim.world.data import load_world
from sim.world.generator import generate
from tests.repo_files import load_file, refused_in_one_line


def load():
    return load_file("scripts/fingerpost_marks.py", "fingerpost_marks")


def test_every_zoo_sign_has_the_mark_and_a_buildings_fingerposts_have_it_more_often_than_its_wayfinding_signs():
    script = load()
    zoo = script.marks(load_world("zoo"))
    assert zoo[True] == 6 and zoo[False] == 0  # every fingerpost of the zoo points back through its own wall
    way, post = (script.marks(generate(seed, style="hospital", arrows=arrows).world)
                 for seed, arrows in ((0, "way"), (0, "bearing")))
    assert sum(way.values()) == sum(post.values()) > 0  # the same signs, written both ways
    assert post[True] > way[True]


def test_the_command_line_prints_one_line_for_a_world_and_refuses_an_unknown_one_in_one_line(capsys):
    script = load()
    assert script.main(["--world", "zoo"]) == 0
    assert re.fullmatch(r"zoo +signs +6 +with the mark +6 +share 1\.000\n", capsys.readouterr().out)
    err = refused_in_one_line(script.main, ["--world", "no-such-world"], capsys, "fingerpost_marks")
    assert "no-such-world" in err


def test_the_development_buildings_are_counted_by_style_and_reading_with_the_likelihood_ratios(capsys):
    script = load()
    assert script.main(["0", "0"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^office, way +signs +\d+", out, re.MULTILINE)
    assert re.search(r"^all, bearing +signs +\d+ +with the mark +\d+ +share 0\.\d+$", out, re.MULTILINE)
    assert re.search(r"^likelihood ratio: a sign with the mark \d+\.\d, without 0\.\d+$", out, re.MULTILINE)
