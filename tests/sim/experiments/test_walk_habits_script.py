"""``scripts/walk_habits.py``: the habits of a study's walks, per navigator, beside the oracle's."""

from __future__ import annotations

import json

import pytest

from tests.repo_files import load_file, refused_in_one_line
from tests.sim.conftest import write_world


def load():
    return load_file("scripts/walk_habits.py", "walk_habits")


def study(tmp_path, trajectories: dict[str, list[tuple[float, float]]]):
    """A study folder over the tiny world holding one trial per navigator, walking through the given points."""
    folder = tmp_path / "study"
    write_world(folder / "worlds" / "tiny")
    (folder / "trials" / "tiny").mkdir(parents=True)
    for navigator, points in trajectories.items():
        record = {"world": "tiny", "goal": "A", "seed": 0, "perception": "geometric", "navigator": navigator,
                  "success": True, "spl": 0.5, "distance_m": 10.0, "signage": None,
                  "trajectory": [[0.4 * i, x, y, 0.0] for i, (x, y) in enumerate(points)]}
        (folder / "trials" / "tiny" / f"{navigator}-A-0.json").write_text(json.dumps(record))
    return folder


def test_each_navigator_and_the_oracle_get_a_row(tmp_path, capsys):
    shuttle = [(1.0 + 0.1 * i, 1.0) for i in range(40)] + [(5.0 - 0.1 * i, 1.0) for i in range(40)]
    straight = [(1.0, 1.0 + 0.1 * i) for i in range(50)]
    assert load().main([str(study(tmp_path, {"guided": shuttle, "paper": straight}))]) == 0
    rows = {line.split("|")[1].strip(): line for line in capsys.readouterr().out.splitlines()[2:]}
    assert set(rows) == {"guided", "paper", "oracle"}
    assert float(rows["guided"].split("|")[5]) == pytest.approx(100 / 7.9, abs=0.05)  # one turn round in 7.9 m
    assert float(rows["paper"].split("|")[5]) == 0.0
    assert rows["oracle"].split("|")[3].strip() == "1"  # the goal once, whoever walked it


def test_a_folder_without_trials_is_one_line_and_exit_2(tmp_path, capsys):
    err = refused_in_one_line(load().main, [str(tmp_path)], capsys, "walk_habits")
    assert str(tmp_path) in err
