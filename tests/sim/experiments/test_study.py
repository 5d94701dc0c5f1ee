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
    records = run_study(specs, tmp_path, executor=ProcessExecutor(1))
    assert [r["success"] for r in records] == [True, True]
    assert records[0]["start"] != records[1]["start"]  # the seeds jitter the start
    rows = list(csv.DictReader((tmp_path / "trials.csv").open()))
    assert [(r["goal"], r["seed"], r["success"]) for r in rows] == [("A", "0", "True"), ("A", "1", "True")]
    stamps = {p.name: p.stat().st_mtime_ns for p in (tmp_path / "trials").iterdir()}
    calls = []
    run_study(specs, tmp_path, executor=ProcessExecutor(1),
              progress=lambda done, total, record: calls.append((done, total, record)))
    assert calls == [(2, 2, None)]  # nothing left to run
    assert stamps == {p.name: p.stat().st_mtime_ns for p in (tmp_path / "trials").iterdir()}


def test_a_generated_goal_carries_its_role_into_records_csv_and_resumed_records(tiny_world, tmp_path):
    import json

    made = tmp_path / "made"
    shutil.copytree(tiny_world.root, made)
    meta = json.loads((made / "world.json").read_text())
    meta["generator"] = {"style": "office", "signage": "complete", "goal_roles": {"A": "dead end"}}
    (made / "world.json").write_text(json.dumps(meta))
    specs = plan_specs(load_world(made), 1, "geometric")
    assert [(s.goal, s.style, s.signage, s.role) for s in specs] == [("A", "office", "complete", "dead end")]
    assert tiny_specs(tiny_world, 1)[0].role == ""  # a world the generator did not make has no roles
    out = tmp_path / "study"
    [first] = run_study(specs, out, executor=ProcessExecutor(1))
    assert first["role"] == "dead end"
    assert [r["role"] for r in csv.DictReader((out / "trials.csv").open())] == ["dead end"]
    [path] = (out / "trials").rglob("*.json")
    old = json.loads(path.read_text())
    del old["role"]  # as written before roles were recorded
    path.write_text(json.dumps(old))
    [resumed] = run_study(specs, out, executor=ProcessExecutor(1))
    assert resumed["role"] == "dead end" and resumed["distance_m"] == first["distance_m"]


def test_a_failing_trial_is_recorded_and_the_rest_go_on(tiny_world, tmp_path):
    bad = TrialSpec(str(tiny_world.root), "Narnia", 0, "geometric", study_params("geometric"))
    records = run_study([bad, *tiny_specs(tiny_world, 1)], tmp_path, executor=ProcessExecutor(1))
    assert not records[0]["success"] and "Narnia" in records[0]["reason"]
    assert records[1]["success"]


def test_process_pool_matches_serial(tiny_world, tmp_path):
    specs = tiny_specs(tiny_world)
    serial = run_study(specs, tmp_path / "a", executor=ProcessExecutor(1))
    pooled = run_study(specs, tmp_path / "b", executor=ProcessExecutor(2))
    assert [r["distance_m"] for r in serial] == [r["distance_m"] for r in pooled]


def test_ray_executor_on_a_local_instance(tiny_world, tmp_path):
    ray = pytest.importorskip("ray")
    try:
        records = run_study(tiny_specs(tiny_world, 1), tmp_path, executor=make_executor("ray", 1))
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


def test_study_help_lists_every_csv_column():
    """The help's list of trials.csv columns is written by hand beside CSV_FIELDS: it names each of them."""
    import sim.experiments.study_command as command
    from sim.experiments.study import CSV_FIELDS

    listed = " ".join(command.__doc__.split())
    assert f"DIR/trials.csv ({', '.join(CSV_FIELDS)})" in listed


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


# -- many worlds, navigators, scores ------------------------------------------------------------------------


def test_spl_and_ratio_follow_anderson_et_al():
    from sim.experiments.metrics import oracle_ratio, spl

    assert spl(True, 40.0, 30.0) == pytest.approx(0.75)
    assert spl(True, 29.0, 30.0) == 1.0  # no shorter than the oracle counts as the oracle
    assert spl(False, 10.0, 30.0) == 0.0
    assert spl(True, 40.0, None) is None and spl(False, None, 0.0) is None
    assert oracle_ratio(True, 45.0, 30.0) == pytest.approx(1.5)
    assert oracle_ratio(False, 45.0, 30.0) is None


def test_trial_files_are_safe_and_unique():
    params = study_params("geometric")
    specs = [TrialSpec("w", goal, 0, "geometric", params, world_name=world)
             for goal, world in [("Polar bear", "zoo"), ("Polar_bear", "zoo"), ("../../x", "zoo"),
                                 ("Lion", "../evil"), ("Lion", "zoo")]]
    keys = [s.key for s in specs]
    assert len(set(keys)) == len(keys)
    for key in keys:
        world_part, name = key.split("/")
        assert ".." not in key and world_part not in ("", ".", "..") and "/" not in name and "\\" not in key
    frontier = TrialSpec("w", "Lion", 0, "geometric", params, world_name="zoo", navigator="frontier")
    assert frontier.key != specs[-1].key


def settings_for(world, **changes):
    from dataclasses import replace

    from sim.experiments.study import StudySettings

    return replace(StudySettings(worlds=(str(world.root),), perception="geometric", navigators=("paper",),
                                 trials=1), **changes)


def test_multi_world_study_resumes_across_worlds_and_refuses_other_settings(tiny_world, tmp_path):
    from sim.experiments.study import StudyError
    from sim.experiments.study_run import conduct_study

    twin = tmp_path / "twin"
    shutil.copytree(tiny_world.root, twin)
    meta = (twin / "world.json").read_text().replace('"name": "tiny"', '"name": "twin"')
    (twin / "world.json").write_text(meta)
    settings = settings_for(tiny_world, worlds=(str(tiny_world.root), str(twin)), navigators=("paper", "frontier"))
    out = tmp_path / "study"
    first = conduct_study(settings, out, workers=1)
    assert [(r["world"], r["navigator"]) for r in first.records] == [  # round robin over worlds
        ("tiny", "paper"), ("tiny", "frontier"), ("twin", "paper"), ("twin", "frontier")]
    assert all(r["oracle_m"] > 0 and r["spl"] is not None for r in first.records)
    rows = list(csv.DictReader((out / "trials.csv").open()))
    assert {"world", "navigator", "oracle_m", "spl", "goal", "seed", "distance_m", "reason",
            "explanation", "near_at_m", "seen_at_m"} <= set(rows[0])
    # resume: a trial file removed is the only one run again
    files = sorted((out / "trials").rglob("*.json"))
    assert len(files) == 4
    files[0].unlink()
    calls = []
    conduct_study(settings, out, workers=1, progress=lambda done, total, record: calls.append((done, total)))
    assert calls == [(3, 4), (4, 4)]
    report = (out / "report.md").read_text()
    for section in ("## Over all trials", "### Failures by reason", "### Where the walking went",
                    "### How the walks moved", "### Per world", "worst trials"):
        assert section in report
    moved = report[report.index("### How the walks moved"):report.index("### Per world")]
    assert [line.split("|")[1].strip() for line in moved.splitlines() if line.startswith("| ")][2:] == [
        "frontier", "oracle", "paper"]  # a row per navigator and the oracle's, after the header and its rule
    with pytest.raises(StudyError, match="trials"):
        conduct_study(settings_for(tiny_world, worlds=settings.worlds, navigators=settings.navigators, trials=2),
                      out, workers=1)


def test_summary_groups_scores_and_lists_the_worst(tmp_path):
    from sim.experiments.summary import stats, summary_markdown, worst_trials

    records = [
        {"world": "a", "style": "office", "signage": "complete", "navigator": "paper", "goal": "X", "seed": 0,
         "success": True, "distance_m": 40.0, "oracle_m": 30.0, "spl": 0.75, "oracle_ratio": 4 / 3, "wall_s": 10.0,
         "reason": "goal label read"},
        {"world": "a", "style": "office", "signage": "complete", "navigator": "frontier", "goal": "X", "seed": 0,
         "success": False, "distance_m": 300.0, "oracle_m": 30.0, "spl": 0.0, "oracle_ratio": None, "wall_s": 30.0,
         "reason": "distance cap of 300 m reached", "explanation": "reads no signs: nearest 9.4 m"},
        {"world": "b", "style": "museum", "signage": "sparse", "navigator": "paper", "goal": "Y", "seed": 0,
         "success": True, "distance_m": 20.0, "oracle_m": 20.0, "spl": 1.0, "oracle_ratio": 1.0, "wall_s": 5.0,
         "reason": "goal label read"},
    ]
    paper = stats([r for r in records if r["navigator"] == "paper"])
    assert paper["success"] == 1.0 and paper["spl"] == pytest.approx(0.875) and paper["ratio"] == pytest.approx(7 / 6)
    worst = worst_trials(records, 2)
    assert [r["navigator"] for r in worst] == ["frontier", "paper"] and worst[1]["spl"] == 0.75
    text = summary_markdown(records, worst=worst, pictures=[tmp_path / "w" / "1.png", None], relative_to=tmp_path)
    assert "### By style" in text and "### By signage level" in text and "### By goal role" in text
    assert "| paper | - | 100% (2/2) |" in text  # records without a role are grouped, not dropped
    assert "| frontier | distance cap of N m reached | reads no signs | 1 |" in text
    assert "- *passed edge-on*: within range of the label only beside or behind it" in text  # the legend
    assert "failed: distance cap of 300 m reached; reads no signs: nearest 9.4 m" in text  # the worst trials
    assert "[path](w/1.png)" in text
    assert "| paper | 100% (2/2) | 0.88 | 1.17 |" in text


def test_seed_spread_pools_each_goals_spread_across_its_seeds():
    from sim.experiments.summary import seed_spread, summary_markdown

    def record(goal: str, seed: int, spl: float, navigator: str = "guided") -> dict:
        return {"world": "a", "navigator": navigator, "perception": "geometric", "goal": goal, "seed": seed,
                "success": spl > 0, "distance_m": 30.0 / spl, "oracle_m": 30.0, "spl": spl, "wall_s": 1.0,
                "reason": "goal label read"}

    # X: seeds 0.5, 0.7, 0.9 (squares 0.08, 2 degrees of freedom); Y: 0.4 twice (0, 1): sd sqrt(0.08 / 3)
    records = [record("X", 0, 0.5), record("X", 1, 0.7), record("X", 2, 0.9), record("Y", 0, 0.4),
               record("Y", 1, 0.4), record("Z", 0, 0.1, "paper")]
    spread = seed_spread(records)
    assert set(spread) == {"guided"}  # paper ran each goal once: no spread to tell
    s = spread["guided"]
    assert s.goals == 2 and s.sd == pytest.approx(math.sqrt(0.08 / 3))
    assert s.apart == pytest.approx(3 / 4) and s.alike == pytest.approx(1 / 4)  # X's three pairs apart, Y's alike
    assert s.trials_needed == math.ceil(8 * (0.08 / 3) / 0.01 ** 2)
    text = summary_markdown(records, worst=[], pictures=[], relative_to=Path("."))
    assert "### How much a walk depends on its seed" in text
    assert f"| guided | 2 | 0.163 | 75% | 25% | {s.trials_needed} |" in text
    assert "How much a walk" not in summary_markdown(records[:1], worst=[], pictures=[], relative_to=Path("."))


def test_plan_goes_round_robin_over_worlds(tiny_world, tmp_path):
    from sim.experiments.study_run import plan_study
    from sim.world.data import load_world

    twin = tmp_path / "twin"
    shutil.copytree(tiny_world.root, twin)
    (twin / "world.json").write_text((twin / "world.json").read_text().replace('"name": "tiny"', '"name": "twin"'))
    settings = settings_for(tiny_world, trials=2, navigators=("paper", "frontier"))
    specs = plan_study([tiny_world, load_world(twin)], settings)
    assert [(s.seed, s.name, s.navigator) for s in specs] == [
        (0, "tiny", "paper"), (0, "tiny", "frontier"), (0, "twin", "paper"), (0, "twin", "frontier"),
        (1, "tiny", "paper"), (1, "tiny", "frontier"), (1, "twin", "paper"), (1, "twin", "frontier")]
    assert all(s.oracle_m and s.oracle_m > 0 for s in specs)


def test_workers_get_one_thread_unless_the_caller_set_a_count(monkeypatch):
    import os

    from sim.experiments.study import one_thread_per_worker

    monkeypatch.delenv("OMP_NUM_THREADS", raising=False)
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "3")
    with one_thread_per_worker():
        assert os.environ["OMP_NUM_THREADS"] == "1" and os.environ["OPENBLAS_NUM_THREADS"] == "3"
    assert "OMP_NUM_THREADS" not in os.environ and os.environ["OPENBLAS_NUM_THREADS"] == "3"
