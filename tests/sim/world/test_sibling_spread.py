"""``scripts/sibling_spread.py``: the measurement behind ``BeliefParams.family_sigma_m``."""

from __future__ import annotations

from tests.repo_files import load_file


def load():
    return load_file("scripts/sibling_spread.py", "sibling_spread")


def test_sibling_labels_hang_within_the_building_and_apart(capsys):
    script = load()
    distances = script.sibling_distances(0, "office")
    assert len(distances) > 20
    assert 0.0 < min(distances) and max(distances) < 60.0  # a medium building is about 45 m across
    assert script.main(["0", "0"]) == 0
    assert "per-axis rms" in capsys.readouterr().out
