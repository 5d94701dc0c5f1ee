"""Study folders (issue 9, item 5): settings recorded, safe unique names, corrupt records re-run.

Trials are faked, so these tests run no simulator.
"""

from __future__ import annotations

import csv
import json

from sim.experiments.study import TrialSpec, plan_specs, run_study


class FakeExecutor:
    """Runs nothing: every spec 'finds' its goal at once; remembers what it was asked to run."""

    def __init__(self) -> None:
        self.ran: list[TrialSpec] = []
        self.units: list[tuple[TrialSpec, ...]] = []

    def map_unordered(self, fn, units):
        for unit in units:
            self.units.append(unit)
            self.ran.extend(unit)
            yield unit, [fake_run(spec) for spec in unit]


def fake_run(spec: TrialSpec) -> dict:
    return {"world": spec.name, "navigator": spec.navigator, "goal": spec.goal, "seed": spec.seed,
            "perception": spec.perception, "success": True,
            "reason": "found", "distance_m": 10.0 + spec.seed, "sim_s": 5.0, "wall_s": 0.1,
            "trajectory": [[0.0, 2.0, 2.0], [1.0, 2.5, 2.0]]}


def test_issue9_item5_duplicate_goals_run_once(tiny_world, tmp_path):
    specs = plan_specs(tiny_world, 2, "geometric", goals=["A", "A"])
    assert [(s.goal, s.seed) for s in specs] == [("A", 0), ("A", 1)]


def test_issue9_item5_a_corrupt_record_is_run_again(tiny_world, tmp_path):
    specs = plan_specs(tiny_world, 2, "geometric")
    run_study(specs, tmp_path, executor=FakeExecutor())
    (tmp_path / "trials" / f"{specs[0].key}.json").write_text('{"goal": "A", "se')
    (tmp_path / "trials" / f"{specs[1].key}.json").write_text(json.dumps(fake_run(specs[0])))  # another trial's
    again = FakeExecutor()
    records = run_study(specs, tmp_path, executor=again)
    assert [s.seed for s in again.ran] == [0, 1]
    assert [r["seed"] for r in records] == [0, 1]
    assert len(list(csv.DictReader((tmp_path / "trials.csv").open()))) == 2


def test_a_goal_readable_from_the_start_reports_without_dividing_by_zero(tiny_world):
    from sim.experiments.report import GoalRow, report_markdown

    row = GoalRow(goal="A", human=[], paper_robot=[], ours=[0.0], failures=0, oracle_m=0.0)
    assert "| A |" in report_markdown(tiny_world, [row], perception="geometric", trials=1, wall_s=1.0)


def test_a_goal_blind_navigator_runs_once_per_world_and_seed_for_all_its_goals(tiny_world, tmp_path):
    """frontier reads no sign: its trials of every goal share one run; paper's each run alone."""
    from dataclasses import replace

    base = plan_specs(tiny_world, 2, "geometric", navigators=("paper", "frontier"))
    specs = base + [replace(s, goal="B") for s in base]  # a second goal (faked: nothing runs)
    executor = FakeExecutor()
    records = run_study(specs, tmp_path, executor=executor)
    shared = [u for u in executor.units if u[0].navigator == "frontier"]
    alone = [u for u in executor.units if u[0].navigator == "paper"]
    assert sorted(len(u) for u in shared) == [2, 2] and {tuple(s.goal for s in u) for u in shared} == {("A", "B")}
    assert all(len({(s.seed, s.world) for s in u}) == 1 for u in shared)  # one world and seed per run
    assert len(alone) == 4 and all(len(u) == 1 for u in alone)
    assert len(records) == 8
