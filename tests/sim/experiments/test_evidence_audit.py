"""The evidence audit: a factor's information gain at the truth, and a variant judged against the same belief."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sim.experiments.evidence_audit import BELIEF, Variant, audit_trial, gain, share_gain, truth_cells
from sim.mapping.occupancy import OccupancyGrid, OccupancyParams


def belief_with(prior: np.ndarray, factor: np.ndarray) -> np.ndarray:
    b = prior * factor
    return b / b.sum()


def test_a_flat_factor_says_nothing_and_a_peaked_one_gains_where_it_points():
    prior = np.full((4, 4), 1.0 / 16)
    truth = np.zeros((4, 4), dtype=bool)
    truth[1, 2] = True
    flat = np.full((4, 4), 0.5)
    assert gain(belief_with(prior, flat), flat, truth) == pytest.approx(0.0, abs=1e-12)
    towards = np.where(truth, 1.0, 0.1)
    away = np.where(truth, 0.1, 1.0)
    # towards: the truth's share goes from 1/16 to 1 / (1 + 15 * 0.1); the gain is the log of that ratio
    assert gain(belief_with(prior, towards), towards, truth) == pytest.approx(math.log(16 / 2.5))
    assert gain(belief_with(prior, away), away, truth) == pytest.approx(math.log(0.1 * 16 / (0.1 + 15)))


def test_a_variant_is_judged_against_the_belief_without_the_factor_it_replaces():
    prior = np.linspace(1.0, 2.0, 16).reshape(4, 4)
    prior /= prior.sum()
    truth = np.zeros((4, 4), dtype=bool)
    truth[3, 3] = True
    own = np.where(truth, 0.2, 1.0)
    better = np.where(truth, 1.0, 0.2)
    belief = belief_with(prior, own)
    assert gain(belief, own, truth, better) == pytest.approx(gain(belief_with(prior, better), better, truth))
    assert gain(belief, own, truth, better) > 0 > gain(belief, own, truth)


def test_no_truth_or_no_belief_gives_nan():
    b = np.full((2, 2), 0.25)
    assert math.isnan(gain(b, b, np.zeros((2, 2), dtype=bool)))
    assert math.isnan(gain(np.zeros((2, 2)), b, np.ones((2, 2), dtype=bool)))


def test_a_belief_variant_gains_the_log_of_the_truths_share_ratio():
    truth = np.zeros((2, 2), dtype=bool)
    truth[0, 1] = True
    own = np.array([[0.4, 0.1], [0.3, 0.2]])
    sharper = np.array([[0.1, 0.4], [0.3, 0.2]])
    assert share_gain(own, sharper, truth) == pytest.approx(math.log(4.0))
    assert share_gain(sharper, own, truth) == pytest.approx(-math.log(4.0))
    assert math.isnan(share_gain(own, np.where(truth, 0.0, own), truth))
    assert math.isnan(share_gain(own, own, np.zeros((2, 2), dtype=bool)))


def test_a_belief_variant_takes_only_the_fields_the_belief_is_made_from():
    assert Variant(BELIEF, {"tail_weight": 0.1}).name == "belief: tail_weight=0.1"
    for factor, changes in ((BELIEF, {"read_range_m": 3.0}), (BELIEF, {"spread_deg": 10.0}),
                            ("arrows", {"tail_weight": 0.1}), (BELIEF, {})):
        with pytest.raises(ValueError, match="expected FIELD=NUMBER"):
            Variant(factor, changes)


def test_a_belief_variant_with_the_navigators_own_parameters_gains_nothing():
    """The zoo's Kingfisher, a minute of it: the belief made again with its own tail weight is the belief."""
    record = audit_trial("zoo", "Kingfisher", variants=(Variant(BELIEF, {"tail_weight": 0.3}),
                                                        Variant(BELIEF, {"tail_weight": 0.05})), max_sim_s=60.0)
    same = [s["belief: tail_weight=0.3"] for s in record.samples if "belief: tail_weight=0.3" in s]
    other = [s["belief: tail_weight=0.05"] for s in record.samples if "belief: tail_weight=0.05" in s]
    assert same and np.allclose(same, 0.0)
    assert len(other) == len(same) and all(math.isfinite(g) for g in other) and any(abs(g) > 1e-6 for g in other)


def test_truth_cells_are_the_cells_near_the_label():
    grid = OccupancyGrid(OccupancyParams(resolution_m=0.1, bounds=(0.0, 2.0, 0.0, 1.0)))
    cells = truth_cells(grid, np.array([[0.55, 0.45]]), 0.15)
    xs, ys = grid.cell_axes()
    rows, cols = np.nonzero(cells)
    assert 4 <= len(rows) <= 9
    assert np.all(np.hypot(xs[cols] - 0.55, ys[rows] - 0.45) <= 0.15)


def test_an_unknown_factor_in_a_variant_is_refused_before_the_trial():
    with pytest.raises(ValueError, match="unknown factor"):
        audit_trial("zoo", "Lion", variants=(Variant("compass", {"spread_deg": 5.0}),))


def load_script():
    from tests.repo_files import load_file

    return load_file("scripts/evidence_audit.py", "evidence_audit")


def test_the_script_reads_variants_and_refuses_bad_ones_and_test_seeds(capsys):
    script = load_script()
    v = script.parse_variant("arrows: unseen_detour=1.0, spread_deg=10")
    assert v.factor == "arrows" and dict(v.changes) == {"unseen_detour": 1.0, "spread_deg": 10.0}
    assert v.name == "arrows: unseen_detour=1, spread_deg=10"
    assert dict(script.parse_variant("belief: family_sigma_m=4, tail_weight=0.1").changes) == {
        "family_sigma_m": 4.0, "tail_weight": 0.1}
    for bad in ("compass: spread_deg=1", "arrows spread_deg=1", "arrows: nonsense=1", "arrows: spread_deg=wide",
                "arrows:", "belief: spread_deg=10", "belief: read_range_m=3"):
        with pytest.raises(ValueError, match="--variant"):
            script.parse_variant(bad)
    assert script.main(["--world", "generated:1000-1001"]) == 2
    err = capsys.readouterr().err
    assert "test seeds" in err and len(err.strip().splitlines()) == 1
    assert script.main(["--world", "generated:0", "--variant", "arrows: x=1"]) == 2
    assert script.main(["--world", "no-such-building"]) == 2
    capsys.readouterr()


def test_the_script_names_a_line_of_its_file_that_is_not_an_audited_trial(tmp_path, capsys):
    out = tmp_path / "audit.jsonl"
    out.write_text('{"world": "zoo"}\n')
    assert load_script().main(["--world", "zoo", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "line 1" in err and len(err.strip().splitlines()) == 1


def test_the_script_audits_a_trial_and_resumes_from_its_file(tmp_path, capsys):
    """The zoo's Kingfisher (a short trial): one line written, read back rather than run again."""
    script = load_script()
    out = tmp_path / "audit.jsonl"
    args = ["--world", "zoo", "--goals", "1", "--out", str(out), "--variant", "arrows: spread_deg=10"]
    assert script.main(args) == 0
    first = capsys.readouterr().out
    assert out.read_text().count("\n") == 1
    assert "all: 1 trials" in first and "arrows: spread_deg=10" in first
    assert script.main(args) == 0
    assert out.read_text().count("\n") == 1  # resumed: not run again
    assert capsys.readouterr().out == first


def test_the_guided_policy_keeps_its_evidence_as_named_factors_the_audit_can_make_again():
    """The zoo's Kingfisher, until an arrow is read: the evidence is the product of the factors, each named as in
    EVIDENCE_FACTORS, and each made again from the same map and cues (as the audit makes a variant) is the same."""
    from dataclasses import replace

    from sim.experiments.study import study_params
    from sim.experiments.trial import Trial
    from sim.navigation.policies import EVIDENCE_FACTORS
    from sim.navigation.routes import PathSearches

    with Trial("zoo", "Kingfisher", seed=0, perception="geometric", navigator="guided",
               params=replace(study_params("geometric"), max_sim_s=120.0)) as trial:
        policy = trial.policy
        while not trial.done and "arrows" not in policy.factors:
            grid = trial.grid.copy()
            trial.step(trial.command())
        assert "arrows" in policy.factors, trial.reason
        assert set(policy.factors) <= set(EVIDENCE_FACTORS)
        product = np.prod(np.stack(list(policy.factors.values())), axis=0)
        np.testing.assert_allclose(policy.evidence, product)
        for name, factor in policy.factors.items():
            made = policy.evidence_factors(grid, policy.params.routes, PathSearches(), (name,))[name]
            np.testing.assert_allclose(made, factor, err_msg=name)
