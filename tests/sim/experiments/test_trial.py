"""Closed-loop trials end to end on the tiny world, and the trial command."""

from __future__ import annotations

import json

import numpy as np
import pytest

from sim.experiments.trial import TrialParams, run_trial


@pytest.mark.parametrize("perception", ["geometric", "camera"])
def test_tiny_trial_finds_the_label(tiny_world, perception):
    result = run_trial(tiny_world, "A", seed=1, perception=perception)
    assert result.success, result.reason
    assert result.reason == "goal label read" and result.explanation == ""
    assert result.near_at_m == 0.0  # the start is within 8 m of a pose that reads the label, and sees it
    assert result.seen_at_m == 0.0 and result.to_dict()["seen_at_m"] == 0.0
    assert [c.tag_id for c in result.cues][-1] == 0
    assert 0.0 <= result.distance_m < 3.0
    steps = np.hypot(*np.diff(result.trajectory[:, 1:3], axis=0).T)
    assert result.distance_m == pytest.approx(steps.sum(), rel=0.05)


def test_trial_is_deterministic(tiny_world):
    a = run_trial(tiny_world, "A", seed=3, perception="geometric")
    b = run_trial(tiny_world, "A", seed=3, perception="geometric")
    assert a.distance_m == b.distance_m
    assert np.array_equal(a.trajectory, b.trajectory)


@pytest.mark.parametrize("caps, reason", [({"max_sim_s": 0.0}, "simulated time cap"),
                                          ({"max_distance_m": 0.0}, "distance cap")])
def test_caps_end_a_trial_with_a_reason(tiny_world, caps, reason):
    # The start is 4.03 m from the label, just out of reading range: the cap comes first.
    result = run_trial(tiny_world, "A", perception="geometric", params=TrialParams(**caps))
    assert not result.success and reason in result.reason
    assert result.sim_s == 0.0
    assert result.explanation.startswith("never named: nearest 4.")  # nothing read yet, just out of range


def test_unknown_goal_is_an_error(tiny_world):
    with pytest.raises(ValueError, match="Narnia"):
        run_trial(tiny_world, "Narnia")


def test_trial_command_writes_result_picture_and_animation(tiny_world, tmp_path):
    from abstract_map.cli import main

    out = tmp_path / "run"
    code = main(["trial", "--world", str(tiny_world.root), "--goal", "A", "--perception", "geometric",
                 "--out", str(out), "--record"])
    assert code == 0
    result = json.loads((out / "result.json").read_text())
    assert result["success"] and result["goal"] == "A"
    assert {"distance_m", "sim_s", "wall_s", "cues", "trajectory", "reason"} <= set(result)
    assert result["cues"][-1]["tag_id"] == 0 and "distance_m" in result["cues"][-1]
    assert (out / "trajectory.png").stat().st_size > 10_000
    assert (out / "run.gif").stat().st_size > 1_000


def test_trial_command_rejects_an_unknown_world(tmp_path, capsys):
    from abstract_map.cli import main

    assert main(["trial", "--world", str(tmp_path / "nowhere"), "--goal", "A", "--out", str(tmp_path)]) == 2
    assert "nowhere" in capsys.readouterr().err


def test_one_goal_blind_run_stands_for_one_trial_per_goal(tmp_path):
    """The frontier's path ignores the goal: a shared run watching two goals gives each goal's own trial."""
    from sim.experiments.trial import Trial
    from sim.world.data import load_world
    from sim.world.generator import generated_world

    world = load_world(generated_world(4, style="office", size="small", root=tmp_path))
    goals = ["Design Storeroom", "Admin Office"]  # the first is read within a minute, the second is not
    params = TrialParams(max_sim_s=60.0, start_jitter_m=0.1, detection_noise_m=0.03)
    with Trial(world, goals[0], seed=2, perception="geometric", navigator="frontier", params=params,
               also=goals[1:]) as shared:
        while not shared.done:
            shared.step()
        together = shared.results()
    assert together["Design Storeroom"].success and not together["Admin Office"].success
    assert together["Admin Office"].explanation.split(":")[0] in ("reads no signs", "passed edge-on",
                                                                  "hidden by walls")
    for goal in goals:
        alone = run_trial(world, goal, seed=2, perception="geometric", navigator="frontier", params=params)
        mine = together[goal]
        assert (mine.success, mine.distance_m, mine.sim_s) == (alone.success, alone.distance_m, alone.sim_s)
        assert mine.reason == alone.reason
        assert mine.explanation == alone.explanation
        assert (mine.near_at_m, mine.seen_at_m) == (alone.near_at_m, alone.seen_at_m)
        assert np.allclose(mine.trajectory[-1], alone.trajectory[-1])


def test_only_a_goal_blind_navigator_shares_a_run(tiny_world):
    from sim.experiments.trial import Trial

    with pytest.raises(ValueError, match="reads signs"):
        Trial(tiny_world, "A", perception="geometric", navigator="paper", also=["A"])


def test_settles_stopped_at_their_cap_are_counted_and_warned_once(tiny_world, monkeypatch, caplog):
    from dataclasses import replace

    from abstract_map.model import AbstractMap

    settle = AbstractMap.settle
    monkeypatch.setattr(AbstractMap, "settle", lambda self: replace(settle(self), settled=False))
    with caplog.at_level("WARNING"):
        result = run_trial(tiny_world, "A", seed=1, perception="geometric")
    assert result.unsettled >= 2  # the first placement and one per new cue
    assert result.to_dict()["unsettled"] == result.unsettled
    warnings = [r for r in caplog.records if r.levelname == "WARNING"]
    assert len(warnings) == 1 and f"{result.unsettled} settle(s)" in warnings[0].getMessage()
