"""The campus walk benchmark: its per-settle caps and what it reports of them."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

CAMPUS = Path(__file__).resolve().parent.parent / "benchmarks" / "campus.py"


@pytest.fixture(scope="module")
def campus():
    sys.path.append(str(CAMPUS.parent))
    import campus

    return campus


def test_a_step_cap_stops_every_settle_and_names_the_capped_cues(campus):
    figures = campus.walk(campus.generate(100), max_cues=6, max_steps=2)
    assert figures["converged"] == 0
    assert figures["caps"] == {"steps": 6, "time": 0}
    assert figures["capped_cues"] == [1, 2, 3, 4, 5, 6]
    assert figures["max_steps"] == 2


def test_an_uncapped_walk_names_no_capped_cue(campus):
    figures = campus.walk(campus.generate(100), max_cues=6)
    assert figures["converged"] == 6 and figures["capped_cues"] == []
    assert 0 < figures["median_steps"] <= figures["max_steps"]


@pytest.mark.parametrize("flag", [["--max-steps", "0"], ["--max-seconds", "-1"]])
def test_a_bad_cap_is_refused_with_exit_2(flag):
    done = subprocess.run([sys.executable, str(CAMPUS), "100", "--cues", "1", *flag], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 2
    assert flag[0] in done.stderr.splitlines()[-1] and "Traceback" not in done.stderr
