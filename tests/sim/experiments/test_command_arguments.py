"""Every argument of ``trial`` and ``study`` is checked before any work (issue 9, item 6).

A bad argument exits 2 with one line naming it; a good set reaches the work,
which is faked here (it raises :class:`Reached`), so no simulator runs.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from abstract_map.cli import main
from sim.experiments import study_run, trial
from tests.conftest import slow_property


class Reached(Exception):
    """The command got past its argument checks to the work."""


@pytest.fixture
def no_work(monkeypatch):
    def work(*args, **kwargs):
        raise Reached()

    monkeypatch.setattr(trial, "run_trial", work)
    monkeypatch.setattr(study_run, "run_study", work)


def outcome(argv: list[str], capsys) -> tuple[str, list[str]]:
    try:
        code = main(argv)
    except Reached:
        return "work", []
    except SystemExit as exc:
        code = exc.code
    err = capsys.readouterr().err.strip().splitlines()
    return str(code), err


@pytest.mark.parametrize("extra, flag", [
    (["--max-sim-s", "-5"], "--max-sim-s"), (["--max-sim-s", "nan"], "--max-sim-s"),
    (["--max-sim-s", "inf"], "--max-sim-s"), (["--max-sim-s", "0"], "--max-sim-s"),
    (["--seed", "-1"], "--seed"), (["--goal", "#3"], "--goal"), (["--goal", "Narnia"], "--goal"),
])
def test_issue9_item6_bad_trial_arguments_exit_2_before_work(tiny_world, tmp_path, capsys, no_work, extra, flag):
    argv = ["trial", "--world", str(tiny_world.root), "--goal", "A", "--out", str(tmp_path / "t"), *extra]
    code, err = outcome(argv, capsys)
    assert code == "2" and len(err) == 1 and flag in err[0]


def test_issue9_item6_an_out_that_is_a_file_is_refused_before_the_trial(tiny_world, tmp_path, capsys, no_work):
    existing = tmp_path / "result"
    existing.write_text("an earlier finished trial")
    code, err = outcome(["trial", "--world", str(tiny_world.root), "--goal", "A", "--out", str(existing)], capsys)
    assert code == "2" and "--out" in err[0]
    assert existing.read_text() == "an earlier finished trial"


@slow_property()
@given(max_sim_s=st.one_of(st.none(), st.floats(allow_nan=True, allow_infinity=True).map(repr),
                           st.sampled_from(["abc", "", "1e400", "-0", "30"])),
       seed=st.one_of(st.integers(-5, 2**40).map(str), st.sampled_from(["x", "1.5", str(2**70)])),
       goal=st.sampled_from(["A", "", "#start", "a", " A", "Narnia"]),
       out=st.sampled_from(["t", "file", "file/t", ""]))
def test_trial_arguments_are_checked_before_work(tiny_world, tmp_path_factory, capsys, no_work, max_sim_s, seed,
                                                 goal, out):
    folder = tmp_path_factory.mktemp("trial")
    (folder / "file").write_text("keep")
    argv = ["trial", "--world", str(tiny_world.root), "--goal", goal, "--seed", seed,
            "--out", str(folder / out) if out else ""]
    argv += ["--max-sim-s", max_sim_s] if max_sim_s is not None else []
    code, err = outcome(argv, capsys)

    def valid_cap(text: str | None) -> bool:
        try:
            return text is None or (math.isfinite(float(text)) and 1 <= float(text) <= 1e6)
        except ValueError:
            return False

    valid = (valid_cap(max_sim_s) and seed.isdigit() and int(seed) < 2**32 and goal == "A" and out == "t")
    assert (code == "work") == valid
    if code != "work":
        assert code == "2" and len(err) == 1 and "Traceback" not in err[0]
    assert (folder / "file").read_text() == "keep"


@pytest.mark.parametrize("extra, flag", [
    (["--trials", "0"], "--trials"), (["--trials", "-1"], "--trials"), (["--workers", "0"], "--workers"),
    (["--goals", "A", "A"], "--goals"), (["--goals", "Narnia"], "--goals"),
])
def test_issue9_item6_bad_study_arguments_exit_2_before_work(tiny_world, tmp_path, capsys, no_work, extra, flag):
    code, err = outcome(["study", "--world", str(tiny_world.root), "--out", str(tmp_path / "s"), *extra], capsys)
    assert code == "2" and len(err) == 1 and flag in err[0]
