"""Property-based tests (issue 9): every input either works or gets the project's own error.

Over cue text, scenario files, saved models and the ``imagine`` command's
arguments: an accepted input gives finite results; a refused one raises an
:class:`~abstract_map.errors.AbstractMapError` (one line, the model unchanged)
or exits 2 with one line on the command line; no file is left half-written.
The number of examples comes from the hypothesis profile (tests/conftest.py).
"""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from abstract_map import persistence
from abstract_map.cli import main
from abstract_map.errors import AbstractMapError
from abstract_map.grammar import parse_cue
from tests.conftest import slow_property
from tests.json_edits import leaves, set_path

from .test_imagine_command import GOOD
from .test_reliability import state, zoo_map

NAMES = st.sampled_from(["Lion", "lion", "the Lion", "Giraffe", "Zoo", "X", "Y", "Polar bear", "here", "Here",
                         "#start", "#3", "", " ", "a" * 250, "Ünïcødé", "is", "and", ".", "$UP$"])
PREPOSITIONS = st.sampled_from(["past", "after", "beyond", "before", "towards", "left of", "to the right of",
                                "near", "by", "next to", "between", "in", "within", "under", "is", ""])
ARROWS = st.sampled_from(["$LEFT$", "$RIGHT$", "$UP$", "$DOWN$", "$left$", "$SIDEWAYS$", "$$", "$"])


@st.composite
def cue_lines(draw: st.DrawFn) -> str:
    names = st.lists(NAMES, min_size=1, max_size=4).map(", ".join)
    return draw(st.one_of(
        st.builds(lambda a, p, b: f"{a} is {p} {b}", names, PREPOSITIONS, names),
        st.builds(lambda c, a, p, b: f"from {c}, {a} is {p} {b}", NAMES, names, PREPOSITIONS, names),
        st.builds(lambda a, b, c: f"{a} is between {b} and {c}", NAMES, NAMES, NAMES),
        st.builds(lambda arrow, a: f"{arrow} {a}", ARROWS, names),
        NAMES,
        st.text(alphabet=st.characters(codec="utf-8"), max_size=40),
    ))


CUES = st.lists(cue_lines(), min_size=1, max_size=5).map("\n".join)
NUMBERS = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(min_value=-(10**400),
                                                                                max_value=10**400),
                    st.floats(min_value=-60, max_value=60))
HOSTILE = st.one_of(st.none(), st.booleans(), NUMBERS, st.text(max_size=20), st.just("#start"), st.just([]),
                    st.just({}), st.lists(st.floats(min_value=-50, max_value=50), max_size=4),
                    st.dictionaries(st.text(max_size=5), st.integers(), max_size=2))


def finite(model) -> bool:
    return all(np.all(np.isfinite(xy)) for xy in model.positions.values())


@given(text=CUES, tag=st.one_of(st.integers(0, 40), HOSTILE),
       pose=st.one_of(st.tuples(st.floats(-40, 40), st.floats(-40, 40), st.floats(-4, 4)), HOSTILE),
       kind=st.sampled_from([None, None, "label", "sign", "poster"]), tagged=st.booleans())
def test_any_cue_works_or_is_refused_changing_nothing(text, tag, pose, kind, tagged):
    model = zoo_map()
    before = state(model)
    try:
        if tagged:
            model.observe_tag(tag, text, pose, kind=kind)
        else:
            model.add_clauses(parse_cue(text, kind=kind))
    except AbstractMapError as exc:
        assert "\n" not in str(exc) and str(exc)
        assert state(model) == before
        model.settle()
        return
    model.settle()
    model.settle()
    assert finite(model)






def scenario_strategy() -> st.SearchStrategy[Any]:
    spots = st.sampled_from(leaves(GOOD) + [["extra"], ["steps", 0, "kind"], ["steps", 1, "explored_centre"]])
    mutated = st.builds(lambda path, value: set_path(GOOD, path, value), spots, HOSTILE)
    texts = st.builds(lambda text: set_path(GOOD, ["steps", 1, "text"], text), CUES)
    return st.one_of(mutated, texts, HOSTILE)


@given(data=scenario_strategy())
def test_any_scenario_replays_or_exits_2_with_one_line(tmp_path_factory, capsys, data):
    folder = tmp_path_factory.mktemp("scenario")
    path, out = folder / "s.json", folder / "r.json"
    path.write_text(json.dumps(data, allow_nan=True))
    out.write_text("earlier result")
    code = main(["imagine", str(path), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    if code == 0:
        result = json.loads(out.read_text(), parse_constant=lambda token: pytest.fail(f"{token} in the result"))
        assert all(math.isfinite(v) for step in result["steps"] for xy in step["positions"].values() for v in xy)
    else:
        assert code == 2 and len(err) == 1 and "Traceback" not in err[0]
        assert out.read_text() == "earlier result"
    assert sorted(p.name for p in folder.iterdir()) == ["r.json", "s.json"]  # no temporary left behind


def saved_model() -> dict[str, Any]:
    model = zoo_map()
    model.observe_tag(3, "$UP$ Giraffe\nThe Lion is past the Giraffe", (0.0, 5.0, -math.pi / 2))
    model.set_goal("Lion")
    model.settle()
    return json.loads(json.dumps(persistence.to_dict(model)))


SAVED = saved_model()


@given(path=st.sampled_from(leaves(SAVED)), value=HOSTILE, drop=st.booleans())
def test_any_saved_model_loads_and_settles_or_is_refused(tmp_path_factory, path, value, drop):
    data = copy.deepcopy(SAVED)
    if drop and isinstance(path[-1], str):
        node = data
        for key in path[:-1]:
            node = node[key]
        del node[path[-1]]
    else:
        data = set_path(data, path, value)
    file = tmp_path_factory.mktemp("model") / "m.json"
    file.write_text(json.dumps(data, allow_nan=True))
    try:
        model = persistence.load(file)
    except AbstractMapError as exc:
        assert "\n" not in str(exc)
        return
    model.settle()
    assert finite(model)
    if model.goal is not None:
        assert np.all(np.isfinite(model.goal_estimate()))


SUFFIXES = st.sampled_from(["json", "png", "svg", "pdf", "xyz", "", "json/", "PNG"])


@slow_property()
@given(out=st.tuples(st.sampled_from(["r", "sub/r", "a-file/r", ".", "a-file", "s.json", ""]), SUFFIXES),
       plot=st.one_of(st.none(), st.tuples(st.sampled_from(["p", "a-file/p", "r", "sub"]), SUFFIXES)),
       model=st.one_of(st.none(), st.sampled_from(["m.json", "r.json", "a-file", "s.json"])))
def test_imagine_arguments_are_checked_before_any_work(tmp_path_factory, capsys, out, plot, model):
    folder = tmp_path_factory.mktemp("args")
    (folder / "s.json").write_text(json.dumps(GOOD))
    (folder / "a-file").write_text("keep")
    (folder / "sub").mkdir()

    def name(parts: tuple[str, str]) -> str:
        return str(folder / parts[0]) + (f".{parts[1]}" if parts[1] else "") if parts[0] else ""

    argv = ["imagine", str(folder / "s.json"), "--out", name(out), "--quiet"]
    argv += ["--plot", name(plot)] if plot else []
    argv += ["--save-model", str(folder / model)] if model else []
    try:
        code = main(argv)
    except SystemExit as exc:
        code = exc.code
    err = capsys.readouterr().err.strip().splitlines()
    assert code in (0, 2)
    if code == 2:
        assert len(err) == 1 and "Traceback" not in err[0]
    assert (folder / "a-file").read_text() == "keep" or "a-file" in (model or "")
    assert json.loads((folder / "s.json").read_text()) == GOOD
    assert not [p for p in Path(folder).rglob("*.tmp*")]
