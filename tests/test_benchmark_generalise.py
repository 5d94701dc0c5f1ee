"""The generalisation benchmark end to end on a tiny suite: one test building, a 10 s cap."""

from __future__ import annotations

import sys

import pytest

from tests.repo_files import load_file


def _benchmarks(monkeypatch):
    return load_file("benchmarks/run.py", "benchmarks_run",
                     lambda name, module: monkeypatch.setitem(sys.modules, name, module))


def test_a_shared_run_is_costed_once(monkeypatch):
    run = _benchmarks(monkeypatch)
    record = {"world": "w", "seed": 0, "perception": "geometric"}
    frontier = [{**record, "navigator": "frontier", "cpu_s": c} for c in (4.0, 9.0, 9.0)]  # one run of 9 s
    paper = [{**record, "navigator": "paper", "cpu_s": c} for c in (4.0, 9.0)]  # two runs
    other_seed = [{**record, "seed": 1, "navigator": "frontier", "cpu_s": 2.0}]
    assert run.run_cost(frontier + other_seed, "cpu_s") == 11.0
    assert run.run_cost(paper, "cpu_s") == 13.0


def test_a_tiny_generalise_suite_runs_and_tabulates(tmp_path, capsys, monkeypatch):
    run = _benchmarks(monkeypatch)
    suite = run.GeneraliseSuite(buildings=1, camera_buildings=0, geometric=("frontier", "guided"), max_sim_s=10.0)
    run.bench_generalise(suite, workers=1, out=tmp_path / "gen")
    printed = capsys.readouterr().out
    assert "| geometric  | frontier  | all" in printed and "| geometric  | guided    | all" in printed
    assert "failures explained" in printed and "reads no signs" in printed  # a 10 s frontier run finds nothing
    moved = printed[printed.index("how the walks moved"):]
    assert "| frontier | geometric | 5 |" in moved and "| oracle | geometric | 5 |" in moved  # the goals once
    records = run.finished_trials(tmp_path / "gen")
    assert len(records) == 10  # 5 goals x 2 navigators; the frontier's 5 from one shared run
    assert {r["world"] for r in records} == {"gen-office-medium-sparse-1000"}
    assert all(r["sim_s"] <= 10.5 for r in records)


def test_a_style_fixes_every_building_and_an_unknown_one_is_refused(monkeypatch, capsys):
    run = _benchmarks(monkeypatch)
    assert run.GeneraliseSuite().worlds(30) == "generated:1000-1029"
    assert run.GeneraliseSuite(style="park").worlds(20) == "generated:1000-1019:style=park"
    monkeypatch.setattr(sys, "argv", ["run.py", "generalise", "--style", "castle"])
    with pytest.raises(SystemExit) as exit_:
        run.main()
    assert exit_.value.code == 2
    assert "--style 'castle': expected one of office, hospital, museum, campus, park" in capsys.readouterr().err


def test_fingerposts_run_the_same_buildings_and_an_unknown_reading_is_refused(monkeypatch, capsys):
    run = _benchmarks(monkeypatch)
    assert run.GeneraliseSuite(arrows="bearing").worlds(30) == "generated:1000-1029:arrows=bearing"
    park = run.GeneraliseSuite(style="park", arrows="bearing")
    assert park.worlds(2) == "generated:1000-1001:style=park,arrows=bearing"
    monkeypatch.setattr(sys, "argv", ["run.py", "generalise", "--arrows", "crow"])
    with pytest.raises(SystemExit) as exit_:
        run.main()
    assert exit_.value.code == 2
    assert "--arrows 'crow': expected one of way, bearing" in capsys.readouterr().err
