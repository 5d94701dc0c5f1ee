"""--world specs: names, folders and ranges of generated buildings, and their errors."""

from __future__ import annotations

import pytest

from abstract_map.cli import main
from sim.experiments.world_spec import WorldSpecError, parse_world_spec, resolve_worlds, seed_split
from sim.world.styles import SEED_CYCLE, SIGNAGE, STYLES


def test_a_name_or_folder_is_kept_as_given():
    spec = parse_world_spec("zoo")
    assert spec.path == "zoo" and spec.seeds is None and spec.generated() == []


def test_a_range_cycles_style_and_signage_so_twelve_seeds_cover_every_pair():
    spec = parse_world_spec("generated:1000-1011")
    built = spec.generated()
    assert [g.seed for g in built] == list(range(1000, 1012))
    assert {(g.style, g.signage) for g in built} == {(s, level) for s in SEED_CYCLE for level in SIGNAGE}
    assert all(g.size == "medium" for g in built)
    assert built[0].style == SEED_CYCLE[1000 % len(SEED_CYCLE)]


def test_the_seed_cycle_is_the_one_the_test_split_was_fixed_with_and_park_is_built_only_by_name():
    assert SEED_CYCLE == ("office", "hospital", "museum", "campus")  # every numbered building's style
    assert set(STYLES) - set(SEED_CYCLE) == {"park"}
    assert "park" not in {g.style for g in parse_world_spec("generated:0-99").generated()}
    named = parse_world_spec("generated:4-6:style=park").generated()
    assert [(g.seed, g.style) for g in named] == [(4, "park"), (5, "park"), (6, "park")]
    assert {g.signage for g in named} == set(SIGNAGE)


def test_fixed_options_and_the_other_cycles():
    spec = parse_world_spec("generated:7-9:style=hospital,size=small")
    assert [(g.seed, g.style, g.size) for g in spec.generated()] == [(7, "hospital", "small"), (8, "hospital", "small"),
                                                                     (9, "hospital", "small")]
    assert {g.signage for g in spec.generated()} == set(SIGNAGE)
    one = parse_world_spec("generated:5:signage=sparse")
    assert [(g.seed, g.signage, g.arrows) for g in one.generated()] == [(5, "sparse", "way")]
    posts = parse_world_spec("generated:5-6:style=park,arrows=bearing").generated()
    assert [(g.seed, g.style, g.arrows) for g in posts] == [(5, "park", "bearing"), (6, "park", "bearing")]


@pytest.mark.parametrize("text, words", [
    ("generated:", "expected seeds"),
    ("generated:9-3", "low to high"),
    ("generated:1-2:colour=red", "option 'colour=red'"),
    ("generated:1-2:style=castle", "style 'castle'"),
    ("generated:1-2:style=office,style=museum", "given twice"),
    ("generated:1-2:arrows=crow", "arrows 'crow'"),
    ("generated:0-99999", "at most"),
    ("generated:a-b", "expected seeds"),
    ("", "empty"),
])
def test_bad_specs_say_what_was_expected(text, words):
    with pytest.raises(WorldSpecError, match=words):
        parse_world_spec(text)


def test_seed_splits():
    assert [seed_split(s) for s in (0, 999, 1000, 1999, 2000)] == ["dev", "dev", "test", "test", "other"]


def test_named_worlds_resolve_and_duplicates_drop(tiny_world, tmp_path):
    folders = resolve_worlds([parse_world_spec(str(tiny_world.root)), parse_world_spec(str(tiny_world.root))],
                             tmp_path)
    assert folders == [tiny_world.root.resolve()]


def test_the_command_line_prints_one_line_and_exits_2(tmp_path, capsys):
    assert main(["study", "--world", "generated:5-1", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "low to high" in err[0]
    assert main(["study", "--world", "zoo", "--navigator", "teleport", "--out", str(tmp_path / "y")]) == 2
    assert "teleport" in capsys.readouterr().err
    assert not (tmp_path / "x").exists() and not (tmp_path / "y" / "settings.json").exists()


def test_trial_command_knows_the_navigators(tiny_world, tmp_path, capsys):
    assert main(["trial", "--world", str(tiny_world.root), "--goal", "A", "--navigator", "teleport",
                 "--out", str(tmp_path / "t")]) == 2
    assert "teleport" in capsys.readouterr().err
    assert main(["trial", "--world", str(tiny_world.root), "--goal", "A", "--navigator", "frontier",
                 "--perception", "geometric", "--out", str(tmp_path / "f")]) == 0
    assert '"navigator": "frontier"' in (tmp_path / "f" / "result.json").read_text()
