"""``abstract-map compare``: two studies paired trial by trial, with the change's standard error."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from abstract_map.cli import main
from sim.experiments.compare import CompareError, compare, load_records, markdown


def record(goal: str, spl: float, *, seed: int = 0, navigator: str = "guided", signage: str = "complete",
           distance_m: float = 40.0, success: bool | None = None, **extra) -> dict:
    found = spl > 0 if success is None else success
    return {"world": "gen-office-medium-complete-0", "goal": goal, "seed": seed, "perception": "geometric",
            "navigator": navigator, "success": found, "spl": spl, "distance_m": distance_m, "signage": signage,
            "style": "office", **extra}


def study(folder: Path, records: list[dict]) -> Path:
    for r in records:
        path = folder / "trials" / r["world"] / f"{r['navigator']}-{r['goal']}-{r['seed']}.json"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(r))
    return folder


def test_paired_change_and_its_standard_error(tmp_path):
    base = [record("A", 0.5, distance_m=40), record("B", 0.4, distance_m=50), record("C", 0.0, distance_m=180,
                                                                                     signage="sparse")]
    new = [record("A", 0.6, distance_m=30), record("B", 0.4, distance_m=50), record("C", 0.2, distance_m=90,
                                                                                    signage="sparse")]
    rows = {r.group: r for r in compare(base, new, groups=("signage",)).rows}
    diffs = [0.1, 0.0, 0.2]
    mean = sum(diffs) / 3
    se = math.sqrt(sum((d - mean) ** 2 for d in diffs) / 2) / math.sqrt(3)
    assert rows["all"].trials == 3 and (rows["all"].found_base, rows["all"].found_new) == (2, 3)
    assert rows["all"].change == pytest.approx(mean) and rows["all"].change_se == pytest.approx(se)
    assert rows["all"].spl_base == pytest.approx(0.3) and rows["all"].spl_new == pytest.approx(0.4)
    assert rows["all"].walk_ratio == pytest.approx(math.sqrt(30 / 40 * 50 / 50))  # found by both: A and B
    assert rows["all"].same == 1 and rows["signage=sparse"].same == 0  # B walked alike; C was found by new alone
    assert rows["signage=sparse"].trials == 1 and math.isnan(rows["signage=sparse"].change_se)
    assert rows["signage=sparse"].walk_ratio is None


def test_trials_one_side_ran_are_named_not_dropped():
    base = [record("A", 0.5), record("B", 0.4)]
    new = [record("A", 0.6), record("C", 0.3)]
    result = compare(base, new)
    assert result.rows[0].trials == 1
    assert [k[1] for k in result.only_base] == ["B"] and [k[1] for k in result.only_new] == ["C"]
    text = markdown(result, "main", "change")
    assert "1 trial only in the base study" in text and "1 trial only in the new study" in text


def test_phases_of_the_found_walks():
    base = [record("A", 0.5, distance_m=60, near_at_m=30.0, seen_at_m=50.0)]
    new = [record("A", 0.8, distance_m=40, near_at_m=25.0, seen_at_m=None)]
    row = compare(base, new).rows[0]
    assert row.phases_base == pytest.approx((30.0, 20.0, 10.0))
    assert row.phases_new == pytest.approx((25.0, 15.0, 0.0))


def test_groups_by_goal_role_even_when_the_base_predates_it():
    base = [record("A", 0.5), record("B", 0.4), record("C", 0.3)]  # a study run before roles were recorded
    new = [record("A", 0.6, role="hall"), record("B", 0.2, role="dead end"), record("C", 0.5, role="hall")]
    rows = {r.group: r for r in compare(base, new, groups=("role",)).rows}
    assert set(rows) == {"all", "role=hall", "role=dead end"}
    assert rows["role=hall"].trials == 2 and rows["role=hall"].change == pytest.approx(0.15)
    assert rows["role=dead end"].change == pytest.approx(-0.2)
    none = {r.group for r in compare(base, base, groups=("role",)).rows}
    assert none == {"all", "role=-"}


def test_two_navigators_of_one_study(tmp_path):
    folder = study(tmp_path / "dev", [record("A", 0.2, navigator="paper"), record("A", 0.7),
                                      record("B", 0.1, navigator="paper"), record("B", 0.5)])
    with pytest.raises(CompareError, match="twice"):
        compare(load_records(folder), load_records(folder), with_navigator=False)
    result = compare(load_records(folder, "paper"), load_records(folder, "guided"), with_navigator=False)
    assert result.rows[0].trials == 2 and result.rows[0].change == pytest.approx(0.45)


def test_bad_folders_are_refused_by_name(tmp_path):
    with pytest.raises(CompareError, match="no trial records"):
        load_records(tmp_path)
    bad = tmp_path / "bad" / "trials" / "w" / "x.json"
    bad.parent.mkdir(parents=True)
    bad.write_text("{not json")
    with pytest.raises(CompareError, match="x.json"):
        load_records(tmp_path / "bad")
    bad.write_text(json.dumps({"world": "w"}))
    with pytest.raises(CompareError, match="missing goal"):
        load_records(tmp_path / "bad")
    with pytest.raises(CompareError, match="share no trial"):
        compare([record("A", 0.5)], [record("A", 0.5, seed=1)])
    with pytest.raises(CompareError, match="navigator 'frontier'"):
        load_records(study(tmp_path / "one", [record("A", 0.5)]), "frontier")


def test_command_prints_the_table_and_writes_it(tmp_path, capsys):
    base = study(tmp_path / "base", [record("A", 0.5), record("B", 0.4)])
    new = study(tmp_path / "new", [record("A", 0.6), record("B", 0.5)])
    out = tmp_path / "reports" / "against.md"
    assert main(["compare", str(base), str(new), "--by", "none", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "| all | 2 | 2 | 2 | 0.450 | 0.550 | +0.100 ± 0.000 |" in printed
    assert "| walks found by both | walks the same |" in printed
    assert out.read_text() == printed


@pytest.mark.parametrize("argv, message", [
    (["{base}", "{tmp}/nowhere"], "not a folder"),
    (["{base}", "{base}", "--by", "colour"], "unknown field 'colour'"),
    (["{base}", "{tmp}"], "no trial records"),
    (["{base}", "{base}", "--out", "{tmp}/report.txt"], "suffixes"),
])
def test_command_bad_input_is_one_line_and_exit_2(tmp_path, capsys, argv, message):
    base = study(tmp_path / "base", [record("A", 0.5)])
    args = [a.format(base=base, tmp=tmp_path) for a in argv]
    assert main(["compare", *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0]


def test_a_studys_world_is_its_own_generated_building_first_then_a_named_world(tmp_path):
    from sim.experiments.compare import study_world
    from sim.world.data import WorldError
    from tests.sim.conftest import write_world

    write_world(tmp_path / "b" / "worlds" / "tiny")
    assert study_world([tmp_path / "a", tmp_path / "b"], "tiny").root == tmp_path / "b" / "worlds" / "tiny"
    assert study_world([tmp_path / "a"], "zoo").name == "zoo"  # not in the study: the named world
    with pytest.raises(WorldError, match="nowhere"):
        study_world([tmp_path / "b"], "nowhere")
