"""Study folders (issue 9, item 5): settings recorded, safe unique names, corrupt records re-run.

Trials are faked, so these tests run no simulator.
"""

from __future__ import annotations

import csv
import json

import pytest

from abstract_map.cli import main
from sim.experiments import study
from sim.experiments.study import StudyError, TrialSpec, plan_specs, run_study, study_params


class FakeExecutor:
    """Runs nothing: every spec 'finds' its goal at once; remembers what it was asked to run."""

    def __init__(self) -> None:
        self.ran: list[TrialSpec] = []

    def map_unordered(self, fn, specs):
        for spec in specs:
            self.ran.append(spec)
            yield spec, fake_run(spec)


def fake_run(spec: TrialSpec) -> dict:
    return {"goal": spec.goal, "seed": spec.seed, "perception": spec.perception, "success": True,
            "reason": "found", "distance_m": 10.0 + spec.seed, "sim_s": 5.0, "wall_s": 0.1,
            "trajectory": [[0.0, 2.0, 2.0], [1.0, 2.5, 2.0]]}


def test_issue9_item5_a_resume_with_other_settings_is_refused(tiny_world, tmp_path):
    run_study(tiny_world, plan_specs(tiny_world, 1, "geometric"), tmp_path, executor=FakeExecutor())
    with pytest.raises(StudyError, match="perception"):
        run_study(tiny_world, plan_specs(tiny_world, 1, "camera"), tmp_path, executor=FakeExecutor())
    more = FakeExecutor()  # more trials, same settings: a legitimate resume
    records = run_study(tiny_world, plan_specs(tiny_world, 3, "geometric"), tmp_path, executor=more)
    assert [s.seed for s in more.ran] == [1, 2] and len(records) == 3


def test_issue9_item5_duplicate_goals_run_once(tiny_world, tmp_path):
    specs = plan_specs(tiny_world, 2, "geometric", goals=["A", "A"])
    assert [(s.goal, s.seed) for s in specs] == [("A", 0), ("A", 1)]


def test_issue9_item5_a_corrupt_record_is_run_again(tiny_world, tmp_path):
    specs = plan_specs(tiny_world, 2, "geometric")
    run_study(tiny_world, specs, tmp_path, executor=FakeExecutor())
    (tmp_path / "trials" / f"{specs[0].key}.json").write_text('{"goal": "A", "se')
    (tmp_path / "trials" / f"{specs[1].key}.json").write_text(json.dumps(fake_run(specs[0])))  # another trial's
    again = FakeExecutor()
    records = run_study(tiny_world, specs, tmp_path, executor=again)
    assert [s.seed for s in again.ran] == [0, 1]
    assert [r["seed"] for r in records] == [0, 1]
    assert len(list(csv.DictReader((tmp_path / "trials.csv").open()))) == 2


def test_issue9_item5_file_names_are_safe_and_unique(tiny_world, tmp_path):
    params = study_params("geometric")
    specs = [TrialSpec(str(tiny_world.root), goal, 0, "geometric", params)
             for goal in ["Polar bear", "Polar_bear", "../../x", "/etc/passwd", "A"]]
    assert len({s.key for s in specs}) == len(specs)
    out = tmp_path / "deep" / "out"
    records = run_study(tiny_world, specs, out, executor=FakeExecutor())
    assert [r["goal"] for r in records] == [s.goal for s in specs]
    written = [p for p in tmp_path.rglob("*") if p.is_file()]
    assert all(out in p.parents for p in written)
    assert specs[0].key == "Polar_bear-0"  # plain names keep the names earlier studies used


@pytest.fixture
def fake_trials(monkeypatch):
    monkeypatch.setattr(study, "run_spec", fake_run)


def test_issue9_item5_the_command_refuses_a_differing_resume(tiny_world, tmp_path, capsys, fake_trials):
    base = ["study", "--world", str(tiny_world.root), "--trials", "1", "--workers", "1", "--out", str(tmp_path)]
    assert main([*base, "--perception", "geometric"]) == 0
    capsys.readouterr()
    assert main([*base, "--perception", "camera"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "perception" in err[0]
    assert main([*base, "--perception", "geometric", "--goals", "A", "A"]) == 2
    assert "--goals" in capsys.readouterr().err


def test_a_goal_readable_from_the_start_reports_without_dividing_by_zero(tiny_world):
    from sim.experiments.report import GoalRow, report_markdown

    row = GoalRow(goal="A", human=[], paper_robot=[], ours=[0.0], failures=0, oracle_m=0.0)
    assert "| A |" in report_markdown(tiny_world, [row], perception="geometric", trials=1, wall_s=1.0)
