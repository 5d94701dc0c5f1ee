"""Rerun recordings of trials, read back through rerun's own reader."""

from __future__ import annotations

import pytest

from sim.experiments.trial import run_trial

WORLD = {"world", "world/floorplan", "world/tags", "world/robot", "world/robot/body", "world/robot/laser",
         "world/path", "world/occupancy", "world/cues", "world/abstract_map/places", "world/abstract_map/goal",
         "world/abstract_map/fixed", "world/abstract_map/springs", "world/target", "cues", "events"}


def entities(path):
    from rerun.chunk import RrdReader

    return {e.lstrip("/") for e in RrdReader(path).store().schema().entity_paths()}


def column(path, entity, name):
    """Every value logged in ``name`` of ``entity``, flattened over rows."""
    from rerun.chunk import RrdReader

    found = []
    for chunk in RrdReader(path).stream():
        if chunk.entity_path.lstrip("/") == entity:
            found += [v for row in chunk.to_record_batch().column(name).to_pylist() for v in row]
    return found


@pytest.mark.parametrize("perception", ["geometric", "camera"])
def test_a_recorded_trial_holds_every_entity(tiny_world, tmp_path, perception):
    pytest.importorskip("rerun")
    path = tmp_path / "run.rrd"
    result = run_trial(tiny_world, "A", seed=1, perception=perception, log=path)
    assert result.success
    assert [p.name for p in tmp_path.iterdir()] == ["run.rrd"]  # no temporary file left
    found = entities(path)
    assert WORLD <= found, WORLD - found
    cameras = {e for e in found if e.startswith("camera/")}
    if perception == "camera":  # the label is read at the first look, straight ahead (view 0), and outlined
        assert {"camera/view_0", "camera/view_0/tags"} <= cameras
        assert column(path, "camera/view_0/tags", "LineStrips2D:labels") == ["0"]
    else:
        assert cameras == set()  # geometric perception renders no images
    assert any(t.endswith(": A") for t in column(path, "cues", "TextLog:text"))
    assert any("FOUND" in t for t in column(path, "events", "TextLog:text"))


def test_the_trial_command_logs_and_names_the_missing_extra(tiny_world, tmp_path, monkeypatch, capsys):
    pytest.importorskip("rerun")
    from abstract_map.cli import main
    from sim.experiments import recording

    args = ["trial", "--world", str(tiny_world.root), "--goal", "A", "--perception", "geometric",
            "--out", str(tmp_path / "out"), "--log", str(tmp_path / "run.rrd")]
    assert main(args) == 0
    assert "world/robot" in entities(tmp_path / "run.rrd")

    def missing():
        raise recording.MissingExtraError(recording.VIZ_HINT)

    monkeypatch.setattr(recording, "rerun_module", missing)
    assert main(args) == 2
    assert 'abstract-map[viz]' in capsys.readouterr().err


def test_a_study_trial_writes_its_recording(tiny_world, tmp_path):
    pytest.importorskip("rerun")
    from dataclasses import replace

    from sim.experiments.study import plan_specs, run_spec

    spec = replace(plan_specs(tiny_world, 1, "geometric")[0], log_dir=str(tmp_path))
    assert run_spec(spec)["success"]
    assert [p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*.rrd")] == [f"{spec.key}.rrd"]
    assert "world/robot" in entities(tmp_path / f"{spec.key}.rrd")


def test_study_log_writes_a_recording_per_trial(tiny_world, tmp_path):
    pytest.importorskip("rerun")
    from abstract_map.cli import main

    out = tmp_path / "study"
    assert main(["study", "--world", str(tiny_world.root), "--trials", "1", "--perception", "geometric",
                 "--workers", "1", "--log", "--out", str(out)]) == 0
    recordings = list((out / "trials").rglob("*.rrd"))
    assert len(recordings) == 1 and "world/robot" in entities(recordings[0])
