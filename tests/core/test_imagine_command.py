"""The ``abstract-map imagine`` command end to end."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from abstract_map.cli import main

LION = Path(__file__).resolve().parents[2] / "worlds" / "zoo" / "lion_replay.json"


def test_imagine_lion_replay(tmp_path, capsys):
    out = tmp_path / "r.json"
    assert main(["imagine", str(LION), "--out", str(out), "--plot", str(tmp_path / "p.png")]) == 0
    steps = json.loads(out.read_text())["steps"]
    assert len(steps) == 15
    assert set(steps[0]) >= {"settled", "iterations", "wall_s", "positions", "goal"}
    assert "Lion" in steps[-1]["positions"] and len(steps[-1]["goal"]) == 2
    assert (tmp_path / "p.png").exists()
    assert "median settle" in capsys.readouterr().err


def write(tmp_path, data) -> Path:
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data) if not isinstance(data, str) else data)
    return path


GOOD = {"hierarchy": {"Campus": {"A Block": {"Room 1": {}}}}, "start": [0, 0, 90], "goal": "Room 1",
        "steps": [{"text": "$LEFT$ Room 1", "tag": 1, "pose": [0, 2, -90]},
                  {"text": "Room 2 is near Room 1"}]}


def test_inline_hierarchy_and_untagged_cue(tmp_path):
    out = tmp_path / "r.json"
    assert main(["imagine", str(write(tmp_path, GOOD)), "--out", str(out), "--quiet"]) == 0
    last = json.loads(out.read_text())["steps"][-1]
    assert "Room 2" in last["positions"]
    x, y = last["goal"]
    assert x < 0  # a reader facing a sign that faces -y looks toward +y; their left is -x
    assert math.isfinite(y)


@pytest.mark.parametrize("mutate, message", [
    (lambda d: d.update(goal="Narnia"), "goal 'Narnia'"),
    (lambda d: d.update(start=[0, "x", 1]), "start"),
    (lambda d: d["steps"].append({"text": "A is under B"}), "unknown preposition 'under'"),
    (lambda d: d["steps"].append({"text": ""}), "non-empty"),
    (lambda d: d["steps"].append({"text": "A", "tag": 3, "pose": [0, float("nan"), 0]}), "finite"),
    (lambda d: d["steps"].append({"text": "A", "tag": 3}), "go together"),
    (lambda d: d.update(stepz=[]), "did you mean 'steps'"),
    (lambda d: d.update(hierarchy="missing.xml"), "missing.xml"),
])
def test_bad_scenarios_exit_2_with_one_line(tmp_path, capsys, mutate, message):
    data = json.loads(json.dumps(GOOD))
    mutate(data)
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data, allow_nan=True))
    assert main(["imagine", str(path), "--out", str(tmp_path / "r.json")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0]


def test_malformed_json(tmp_path, capsys):
    assert main(["imagine", str(write(tmp_path, "{nope")), "--out", str(tmp_path / "r.json")]) == 2
    assert "not valid JSON" in capsys.readouterr().err
