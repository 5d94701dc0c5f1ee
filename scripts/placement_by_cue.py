"""How far the abstract map places a place it has not seen, by how the cues name it: the goal prior's floors.

Usage: ``python scripts/placement_by_cue.py [FIRST LAST]`` (development seeds, default 12 35) or
``python scripts/placement_by_cue.py --world NAME`` (a world folder or a name under ``worlds/``, e.g. ``zoo``).

For each building, the places with a label are split into four folds. For each fold the abstract map reads
every sign and every label but the fold's, settles, and each held-out place's imagined position is measured
against its nearest label (m). Places are grouped by how the signs name them
(:func:`abstract_map.clauses.named_by`: in a phrase, else in an arrow, else only by the hierarchy), and each
group's rms miss gives the spread a side it stands for, ``sqrt(rms^2 / 2 - l^2)`` with ``l`` the label's
offset from its place (``BeliefParams.label_offset_m``, which ``goal_sigma`` adds in quadrature): what
``BeliefParams.sigma_min_m``, ``sigma_min_arrow_m`` and ``sigma_min_hierarchy_m`` stand for. The seeds are
``generated:FIRST-LAST`` (style and signage cycling with the seed, medium size).
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterable

import numpy as np

from abstract_map.clauses import NAMED_BY, named_by
from abstract_map.hierarchy import Hierarchy
from abstract_map.model import AbstractMap
from sim.experiments.survey import buildings, on_world, survey_parser
from sim.navigation.belief import BeliefParams
from sim.world.data import Tag
from sim.world.generator import generate

FOLDS = 4  # a quarter of the places held out at a time: the rest read, as a robot far into a search has


def held_out_misses(tags: Iterable[Tag], hierarchy: Hierarchy, start: tuple[float, float, float],
                    rng: np.random.Generator, folds: int = FOLDS) -> list[tuple[str, float]]:
    """(how the signs name the place, m from its imagined position to its nearest label) for every labelled
    place, each held out in one of ``folds`` folds (assigned by ``rng``) while the rest is read."""
    tags = list(tags)
    labels: dict[str, list[Tag]] = defaultdict(list)
    for tag in tags:
        if tag.kind == "label":
            labels[tag.text].append(tag)
    clauses = [c for t in tags if t.kind == "sign" for c in t.clauses()]
    places = sorted(labels)
    rng.shuffle(places)
    out = []
    for k in range(folds):
        held = set(places[k::folds])
        model = AbstractMap.from_hierarchy(hierarchy, start)
        for t in tags:
            if t.kind != "empty" and not (t.kind == "label" and t.text in held):
                model.observe_tag(t.id, t.text, (t.x, t.y, t.theta), kind=t.kind)
        model.settle()
        for place in sorted(held):
            x, y = model.position(place)
            miss = min(math.hypot(x - t.x, y - t.y) for t in labels[place])
            out.append((named_by(clauses, place), miss))
    return out


def summary(name: str, misses: list[tuple[str, float]], label_offset_m: float) -> list[str]:
    """One line per way of naming with any place: how many, rms and median miss (m), and the spread a side."""
    lines = []
    for kind in NAMED_BY:
        m = np.array([d for k, d in misses if k == kind])
        if len(m):
            rms = float(np.sqrt(np.mean(m ** 2)))
            side = math.sqrt(max(rms ** 2 / 2 - label_offset_m ** 2, 0.0))
            lines.append(f"{name:10s} {kind:10s} places {len(m):5d}  rms {rms:5.1f} m  median {np.median(m):5.1f} m"
                         f"  spread a side {side:4.1f} m")
    return lines or [f"{name:10s} no labelled place"]


def main(argv: list[str] | None = None) -> int:
    parser = survey_parser(__doc__, (12, 35))
    args = parser.parse_args(argv)
    offset, rng = BeliefParams().label_offset_m, np.random.default_rng(0)
    if args.world:
        misses = on_world(parser, args, "placement_by_cue", lambda world: held_out_misses(
            world.tags.values(), Hierarchy.from_xml(world.hierarchy_path), world.start, rng))
        print("\n".join(summary(args.world, misses, offset)))
        return 0
    misses = []
    for building in buildings(parser, args):
        built = generate(building.seed, style=building.style, signage=building.signage)
        misses += held_out_misses(built.world.tags.values(), built.hierarchy, built.world.start, rng)
    print("\n".join(summary("all", misses, offset)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
