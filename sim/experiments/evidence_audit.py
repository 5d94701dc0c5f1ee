"""Evidence audit: how much each factor of a navigator's goal belief says about where the goal's label hangs.

The guided navigator's belief over the cell holding the goal's label is a
prior times factors (door depth, arrows, signs that do not name the goal; see
``docs/method-notes.md``). Each factor claims to be a likelihood. Whether it
is one shows in trials on development buildings, where the truth is known: a
factor that is calibrated raises the truth's share of the belief on average.

For a belief ``b`` (per cell, summing to 1) that includes a factor ``f`` (per
cell, positive), the belief without it is ``b_f = (b / f) / Z`` with
``Z = sum_x b(x) / f(x)``. The factor's gain at the truth ``g`` (the cells
within ``goal_m`` of the goal's label: its wall cell, as mapped) is

    gain(f) = log f(g) - log sum_x b_f(x) f(x) = log f(g) + log Z

nats: the log of the factor by which ``f`` multiplied the truth's share
(``f(g)``: its most over ``g``). Positive: the factor pointed at the truth;
negative: it led away. A variant ``f'`` of the factor (other parameters, the
same map and cues) is judged against the same ``b_f``:

    gain(f') = log f'(g) - log sum_x b_f(x) f'(x)

so variants can be compared on one run, without a study per setting.

A variant of the whole belief (``belief``: other ``BeliefParams`` fields of
its prior and of its weighing of space, :data:`BELIEF_FIELDS`) is made again
from the same map, cues, swept space and evidence, beside the navigator's own
belief ``b`` made again from the same inputs, and judged by the truth's share:

    gain(b') = log sum_g b'(g) - log sum_g b(g)

nats, the log of the factor by which the variant multiplied the truth's share.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from sim.mapping.occupancy import OccupancyGrid
from sim.navigation.belief import goal_belief
from sim.navigation.policies import EVIDENCE_FACTORS, GuidedPolicy
from sim.navigation.routes import PathSearches, RouteParams

BELIEF = "belief"  # a variant's target when it changes the whole belief rather than one factor
TARGETS = (*EVIDENCE_FACTORS, BELIEF)  # what a variant can be made of: one factor, or the whole belief
BELIEF_FIELDS = ("sigma_min_m", "sigma_min_arrow_m", "sigma_min_hierarchy_m", "sigma_per_m", "label_offset_m",
                 "prior_misses", "tail_weight", "tail_scale", "family_sigma_m", "unknown_wall_prob",
                 "detect_prob")  # the BeliefParams fields the belief is made from, given the space swept (the
# others shape the sweep itself, which a variant does not redo)


def gain(belief: np.ndarray, factor: np.ndarray, truth: np.ndarray, variant: np.ndarray | None = None) -> float:
    """The information gain (nats) at the ``truth`` cells (bool, the belief's shape) of ``factor``, part of
    ``belief`` (module docstring), or of ``variant`` in its place; NaN when the belief is empty or the truth has
    no cell."""
    if not truth.any() or float(belief.sum()) <= 0.0:
        return math.nan
    tiny = 1e-12
    without = belief / np.maximum(factor, tiny)
    without = without / float(without.sum())
    f = factor if variant is None else variant
    return math.log(max(float(f[truth].max()), tiny)) - math.log(max(float(np.sum(without * f)), tiny))


def share_gain(own: np.ndarray, variant: np.ndarray, truth: np.ndarray) -> float:
    """The gain (nats) of the belief ``variant`` over the belief ``own`` (per cell, each summing to 1) at the
    ``truth`` cells: the log of the ratio of the truth's shares; NaN when the truth has no cell or either belief
    puts nothing on it."""
    a, b = float(own[truth].sum()), float(variant[truth].sum())
    return math.log(b / a) if truth.any() and a > 0.0 and b > 0.0 else math.nan


def truth_cells(grid: OccupancyGrid, labels_xy: np.ndarray, goal_m: float) -> np.ndarray:
    """Bool per cell of ``grid``: within ``goal_m`` (m) of any of the goal's labels (``labels_xy``, (K, 2) m)."""
    xs, ys = grid.cell_axes()
    out = np.zeros(grid.shape, dtype=bool)
    for x, y in np.atleast_2d(labels_xy):
        out |= np.hypot(xs[None, :] - x, ys[:, None] - y) <= goal_m
    return out


@dataclass(frozen=True)
class Variant:
    """A factor made again with other route parameters, or the whole belief with other belief parameters,
    judged beside the navigator's own."""

    factor: str  # one of sim.navigation.policies.EVIDENCE_FACTORS, or BELIEF
    changes: Mapping[str, float]  # RouteParams fields (BELIEF_FIELDS for BELIEF) and their values

    def __post_init__(self) -> None:
        if self.factor not in TARGETS:
            raise ValueError(f"variant {self.name!r}: unknown factor {self.factor!r}; known: {list(TARGETS)}")
        fields = BELIEF_FIELDS if self.factor == BELIEF else tuple(RouteParams.__dataclass_fields__)
        wrong = [k for k in self.changes if k not in fields]
        if wrong or not self.changes:
            kind = "BeliefParams field of BELIEF_FIELDS" if self.factor == BELIEF else "RouteParams field"
            raise ValueError(f"variant {self.name!r}: {wrong or 'no change'}; expected FIELD=NUMBER with FIELD a "
                             f"{kind}")

    @property
    def name(self) -> str:
        return f"{self.factor}: " + ", ".join(f"{k}={v:g}" for k, v in self.changes.items())


@dataclass(frozen=True)
class AuditParams:
    """How often and where the audit looks."""

    every_s: float = 5.0  # s of simulated time between samples (the evidence is refreshed every 8 s or so)
    goal_m: float = 0.3  # m about the goal's label counted as the truth: its wall cell as mapped (0.1 m cells)


@dataclass
class AuditRecord:
    """One trial's audit: per sample, the truth's share of the belief and each factor's gain (nats)."""

    world: str
    goal: str
    seed: int
    success: bool = False
    distance_m: float = 0.0
    samples: list[dict[str, float]] = field(default_factory=list)  # "t_s", "distance_m", "share", gains by name

    def mean_gains(self) -> dict[str, float]:
        """Each factor's (and variant's) gain averaged over the samples that had it."""
        names = {k for s in self.samples for k in s} - {"t_s", "distance_m", "share"}
        out = {}
        for name in sorted(names):
            values = [s[name] for s in self.samples if name in s and math.isfinite(s[name])]
            if values:
                out[name] = float(np.mean(values))
        return out


def audit_trial(world: str | Path, goal: str, *, seed: int = 0, perception: str = "geometric",
                variants: tuple[Variant, ...] = (), params: AuditParams = AuditParams(),
                max_sim_s: float = 600.0) -> AuditRecord:
    """Run one guided trial as a study runs it, sampling the gains of the belief's factors (and of ``variants``,
    made again each time the navigator refreshes its evidence) every ``every_s`` of simulated time."""
    from sim.experiments.study import study_params
    from sim.experiments.trial import Trial

    factored = [v for v in variants if v.factor != BELIEF]
    believed = [v for v in variants if v.factor == BELIEF]
    record = AuditRecord(str(world), goal, seed)
    with Trial(world, goal, seed=seed, perception=perception, navigator="guided",
               params=replace(study_params(perception), max_sim_s=max_sim_s)) as trial:
        policy = trial.policy
        labels = np.array([[trial.world.tags[i].x, trial.world.tags[i].y] for i in trial.goal_tags])  # read: found
        searches = PathSearches()
        made: dict[str, np.ndarray] = {}
        made_at, sampled_at = -1, -math.inf
        while not trial.done:
            trial.step(trial.command())
            if policy.evidence_count != made_at:
                made_at = policy.evidence_count
                made = {}
                for v in factored:
                    rp = replace(policy.params.routes, **v.changes)
                    factor = policy.evidence_factors(trial.grid, rp, searches, (v.factor,)).get(v.factor)
                    if factor is not None:
                        made[v.name] = factor
            belief = policy.belief
            if belief is None or trial.t - sampled_at < params.every_s or belief.mass.shape != trial.grid.shape:
                continue
            sampled_at = trial.t
            truth = truth_cells(trial.grid, labels, params.goal_m)
            sample = {"t_s": trial.t, "distance_m": trial.distance, "share": float(belief.mass[truth].sum())}
            for name, factor in policy.factors.items():
                if factor.shape == belief.mass.shape:
                    sample[name] = gain(belief.mass, factor, truth)
            for v in factored:
                own = policy.factors.get(v.factor)
                if v.name in made and own is not None and own.shape == made[v.name].shape == belief.mass.shape:
                    sample[v.name] = gain(belief.mass, own, truth, made[v.name])
            sample.update(belief_gains(policy, trial.grid, truth, believed))
            record.samples.append(sample)
        record.success, record.distance_m = trial.success, trial.distance
    return record


def belief_gains(policy: GuidedPolicy, grid: OccupancyGrid, truth: np.ndarray,
                 believed: list[Variant]) -> dict[str, float]:
    """Each belief variant's gain (:func:`share_gain`) over the guided ``policy``'s own belief, both made again
    on ``grid`` from the policy's latest swept space and evidence, the variant's fields replacing the policy's
    own. Empty when the policy has no belief on this grid yet."""
    swept, evidence = policy.belief_swept, policy.evidence
    if not believed or swept is None or swept.shape != grid.shape or (evidence is not None and
                                                                       evidence.shape != grid.shape):
        return {}
    own = goal_belief(grid, swept, policy.goal_prior(), policy.params.belief, evidence).mass
    out = {}
    for v in believed:
        params = replace(policy.params.belief, **v.changes)
        out[v.name] = share_gain(own, goal_belief(grid, swept, policy.goal_prior(params), params, evidence).mass,
                                 truth)
    return out
