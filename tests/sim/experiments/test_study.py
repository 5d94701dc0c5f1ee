"""The study: resumable, failure-tolerant, executors, and its report against the paper."""

from __future__ import annotations

import csv
import math
import shutil
from pathlib import Path

import pytest

from sim.experiments.report import comparison_plot, goal_rows, load_reference, report_markdown
from sim.experiments.study import ProcessExecutor, TrialSpec, make_executor, plan_specs, run_study, study_params
from sim.world.data import load_world
from sim.world.oracle import oracle_path

ZOO = Path(__file__).resolve().parents[3] / "worlds" / "zoo"


def tiny_specs(world, trials=2):
    return plan_specs(world, trials, "geometric")


def test_specs_vary_by_seed_and_carry_the_variation(tiny_world):
    specs = tiny_specs(tiny_world, 3)
    assert [(s.goal, s.seed) for s in specs] == [("A", 0), ("A", 1), ("A", 2)]
    assert specs[0].params.start_jitter_m == 0.10 and specs[0].params.detection_noise_m == 0.03
    assert study_params("camera").detection_noise_m == 0.0


def test_study_runs_resumes_and_writes_csv(tiny_world, tmp_path):
    specs = tiny_specs(tiny_world)
    records = run_study(tiny_world, specs, tmp_path, executor=ProcessExecutor(1))
    assert [r["success"] for r in records] == [True, True]
    assert records[0]["start"] != records[1]["start"]  # the seeds jitter the start
    rows = list(csv.DictReader((tmp_path / "trials.csv").open()))
    assert [(r["goal"], r["seed"], r["success"]) for r in rows] == [("A", "0", "True"), ("A", "1", "True")]
    stamps = {p.name: p.stat().st_mtime_ns for p in (tmp_path / "trials").iterdir()}
    calls = []
    run_study(tiny_world, specs, tmp_path, executor=ProcessExecutor(1),
              progress=lambda done, total, record: calls.append((done, total, record)))
    assert calls == [(2, 2, None)]  # nothing left to run
    assert stamps == {p.name: p.stat().st_mtime_ns for p in (tmp_path / "trials").iterdir()}


def test_a_failing_trial_is_recorded_and_the_rest_go_on(tiny_world, tmp_path):
    bad = TrialSpec(str(tiny_world.root), "Narnia", 0, "geometric", study_params("geometric"))
    records = run_study(tiny_world, [bad, *tiny_specs(tiny_world, 1)], tmp_path, executor=ProcessExecutor(1))
    assert not records[0]["success"] and "Narnia" in records[0]["reason"]
    assert records[1]["success"]


def test_process_pool_matches_serial(tiny_world, tmp_path):
    specs = tiny_specs(tiny_world)
    serial = run_study(tiny_world, specs, tmp_path / "a", executor=ProcessExecutor(1))
    pooled = run_study(tiny_world, specs, tmp_path / "b", executor=ProcessExecutor(2))
    assert [r["distance_m"] for r in serial] == [r["distance_m"] for r in pooled]


def test_ray_executor_on_a_local_instance(tiny_world, tmp_path):
    ray = pytest.importorskip("ray")
    try:
        records = run_study(tiny_world, tiny_specs(tiny_world, 1), tmp_path, executor=make_executor("ray", 1))
    finally:
        ray.shutdown()
    assert records[0]["success"]


def test_unknown_executor_is_an_error():
    with pytest.raises(ValueError, match="dask"):
        make_executor("dask", 1)


def fake_records():
    out = []
    for goal, distances in {"Lion": [44.0, 46.0], "Toilets": [30.0]}.items():
        out += [{"goal": goal, "seed": i, "success": True, "distance_m": d} for i, d in enumerate(distances)]
    out.append({"goal": "Toilets", "seed": 1, "success": False, "distance_m": math.nan})
    return out


def test_report_extends_table_one():
    zoo = load_world(ZOO)
    reference = load_reference(zoo)
    assert sum(reference["Lion"]["human"]) / 5 == pytest.approx(49.4, abs=0.05)
    assert sum(reference["Polar bear"]["robot"]) / 5 == pytest.approx(40.5, abs=0.05)
    rows = goal_rows(zoo, fake_records(), {})
    text = report_markdown(zoo, rows, perception="geometric", trials=2, wall_s=60.0)
    lion = next(line for line in text.splitlines() if line.startswith("| Lion"))
    cells = [c.strip() for c in lion.strip("|").split("|")]
    assert cells[1:4] == ["49.4", "45.6", "45.0"]
    human = sum(reference["Lion"]["human"]) / 5
    assert cells[6] == f"{(1 - 45.0 / human) * 100:.1f}"
    assert "Toilets 1" in text  # the failure is reported, not averaged in


def test_report_with_oracle_and_plot(tmp_path):
    zoo = load_world(ZOO)
    oracles = {"Lion": oracle_path(zoo, "Lion")}
    rows = goal_rows(zoo, fake_records()[:2], oracles)
    assert 40.0 < rows[0].oracle_m < 45.0
    text = report_markdown(zoo, rows, perception="camera", trials=2, wall_s=1.0)
    assert f"{45.0 / rows[0].oracle_m:.2f}" in text
    comparison_plot(rows, tmp_path / "comparison.png")
    assert (tmp_path / "comparison.png").stat().st_size > 10_000


def test_study_command_end_to_end(tiny_world, tmp_path):
    from abstract_map.cli import main

    world = tmp_path / "tiny"
    shutil.copytree(tiny_world.root, world)
    (world / "paper_trials.csv").write_text("goal,navigator,trial,distance_m\nA,human,1,3.0\nA,robot,1,2.5\n")
    out = tmp_path / "study"
    assert main(["study", "--world", str(world), "--trials", "2", "--workers", "1", "--perception", "geometric",
                 "--out", str(out)]) == 0
    for name in ("trials.csv", "report.md", "comparison.png", "paths/A.png", "paper_trials.csv"):
        assert (out / name).exists(), name
    assert "| A | 3.0 | 2.5 |" in (out / "report.md").read_text()
