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
    assert result.reason == "goal label read"
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
