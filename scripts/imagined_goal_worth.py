"""What the abstract map's imagined goal is worth to a walk: is it nearer the goal's label than a point anywhere?

Usage: ``python scripts/imagined_goal_worth.py [FIRST LAST]`` (development seeds, default 64 83: each
building's first goal) or ``python scripts/imagined_goal_worth.py --world NAME`` (every goal of a world folder
or a name under ``worlds/``, e.g. ``zoo``). ``--stride`` (m walked between samples, default 5) and
``--max-sim-s`` (each walk's cap, default 600).

Each goal is walked once by the default navigator (guided, geometric perception, seed 0). Every ``stride`` m
walked, the imagined goal (the prior's centre) is measured against the goal's nearest label (m), and against
the median distance from that label to points drawn evenly over the building's free floor: a prior that knows
nothing puts the goal there. Samples are grouped by how the cues read so far name the goal
(:func:`abstract_map.clauses.named_by`). Per group: the samples, the median miss, the median distance of an
even point, the share of samples where the imagined goal is the nearer, and the rms of ``miss / (sqrt(2)
sigma)`` with ``sigma`` the prior's spread (1 when the spread is calibrated). The floor is the world's truth,
read here to judge the model, never by the robot.
"""

from __future__ import annotations

import math
import tempfile
from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from abstract_map.clauses import NAMED_BY
from sim.experiments.study import study_params
from sim.experiments.survey import buildings, on_world, survey_parser
from sim.experiments.trial import Trial, TrialParams
from sim.world.data import World, load_world
from sim.world.generator import generated_world

EVEN_POINTS = 4000  # points drawn over the free floor per world: the median distance to them to ~1%


@dataclass(frozen=True)
class Sample:
    """The imagined goal at one moment of a walk."""

    walked_m: float  # m walked so far
    placed_by: str  # how the cues read so far name the goal (NAMED_BY)
    miss_m: float  # m, imagined goal to the goal's nearest label
    even_m: float  # m, median distance from that label to a point drawn evenly over the free floor
    sigma_m: float  # m, the spread the goal's prior claims


def free_points(world: World, n: int, rng: np.random.Generator) -> np.ndarray:
    """(n, 2) m: points drawn evenly over the free cells of ``world``'s floor plan (cell centres, world frame)."""
    plan = world.floorplan
    free = np.argwhere(~plan.occupied)
    return plan.pixel_to_world(free[rng.integers(0, len(free), n)])


def even_distance(labels_xy: np.ndarray, points_xy: np.ndarray) -> float:
    """Median over ``points_xy`` (N, 2 m) of the distance (m) to the nearest of ``labels_xy`` (K, 2 m)."""
    labels, points = np.atleast_2d(labels_xy), np.atleast_2d(points_xy)
    d = np.hypot(points[:, None, 0] - labels[None, :, 0], points[:, None, 1] - labels[None, :, 1])
    return float(np.median(d.min(axis=1)))


def walk_samples(world: World, goal: str, stride_m: float, max_sim_s: float,
                 rng: np.random.Generator) -> list[Sample]:
    """Walk ``goal`` in ``world`` once (guided, geometric, seed 0) and sample the imagined goal every
    ``stride_m`` m walked."""
    labels = np.array([(t.x, t.y) for t in world.label_tags(goal)])
    even = even_distance(labels, free_points(world, EVEN_POINTS, rng))
    params = study_params("geometric", TrialParams(max_sim_s=max_sim_s))
    out, next_m = [], 0.0
    with Trial(world, goal, seed=0, perception="geometric", navigator="guided", params=params) as trial:
        while not trial.done:
            trial.step()
            if trial.distance < next_m:
                continue
            next_m += stride_m
            prior = trial.policy.goal_prior()
            miss = float(np.min(np.hypot(*(labels - prior.centre).T)))
            out.append(Sample(trial.distance, trial.policy.placed_by(), miss, even, prior.sigma_m))
    return out


def summary(name: str, samples: Iterable[Sample]) -> list[str]:
    """One line per way of naming with any sample: samples, median miss and even distance (m), the share the
    imagined goal is the nearer, and the rms calibration ``miss / (sqrt(2) sigma)``."""
    by: dict[str, list[Sample]] = defaultdict(list)
    for s in samples:
        by[s.placed_by].append(s)
    lines = []
    for kind in NAMED_BY:
        if not by[kind]:
            continue
        miss = np.array([s.miss_m for s in by[kind]])
        even = np.array([s.even_m for s in by[kind]])
        z = miss / (math.sqrt(2) * np.array([s.sigma_m for s in by[kind]]))
        lines.append(f"{name:10s} {kind:10s} samples {len(miss):4d}  miss median {np.median(miss):5.1f} m  "
                     f"an even point {np.median(even):5.1f} m  nearer {np.mean(miss < even):4.0%}  "
                     f"calibration {np.sqrt(np.mean(z ** 2)):4.2f}")
    return lines or [f"{name:10s} no sample"]


def world_samples(world: World, goals: Sequence[str], stride_m: float, max_sim_s: float,
                  rng: np.random.Generator) -> list[Sample]:
    out = []
    for goal in tqdm(goals, desc=world.name, leave=False):
        out += walk_samples(world, goal, stride_m, max_sim_s, rng)
    return out


def main(argv: list[str] | None = None) -> int:
    parser = survey_parser(__doc__, (64, 83))
    parser.add_argument("--stride", type=float, default=5.0, help="m walked between samples (default 5)")
    parser.add_argument("--max-sim-s", type=float, default=600.0, help="each walk's cap, s (default 600)")
    args = parser.parse_args(argv)
    if not (args.stride > 0 and args.max_sim_s > 0):
        parser.exit(2, f"imagined_goal_worth: --stride and --max-sim-s must be positive metres and seconds, "
                       f"got {args.stride:g} and {args.max_sim_s:g}\n")
    rng = np.random.default_rng(0)
    if args.world:
        samples = on_world(parser, args, "imagined_goal_worth", lambda world: world_samples(
            world, sorted(world.goals), args.stride, args.max_sim_s, rng))
        print("\n".join(summary(args.world, samples)))
        return 0
    samples = []
    with tempfile.TemporaryDirectory() as root:  # a walk loads its world from a folder
        for building in buildings(parser, args):
            world = load_world(generated_world(building.seed, style=building.style, signage=building.signage,
                                               root=Path(root)))
            samples += world_samples(world, sorted(world.goals)[:1], args.stride, args.max_sim_s, rng)
    print("\n".join(summary("all", samples)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
