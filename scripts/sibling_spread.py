"""How far apart the labels of sibling places hang on generated buildings: the guided prior's family spread.

Usage: ``python scripts/sibling_spread.py [FIRST LAST]`` (development seeds, default 0 99). For every pair of
label tags whose places share a parent area (not the building's root), the distance between the tags (m);
prints the median, the per-axis rms (``BeliefParams.family_sigma_m``) and the same per style. Seed ``s`` is
style ``STYLES[s % 4]``, medium size, complete signage (the layout does not depend on the signage).
"""

from __future__ import annotations

import sys
from collections import defaultdict

import numpy as np
from tqdm import tqdm

from sim.experiments.world_spec import parse_world_spec
from sim.world.generator import generate


def sibling_distances(seed: int, style: str) -> list[float]:
    """Distances (m) between the labels of every two places of ``seed``'s building with the same parent area."""
    built = generate(seed, style=style)
    parent = built.hierarchy.parent
    labels = [t for t in built.world.tags.values() if t.kind == "label"]
    out = []
    for i, a in enumerate(labels):
        area = parent.get(a.text)
        if area is None or area not in parent:  # a place of the building itself: no area
            continue
        out += [float(np.hypot(a.x - b.x, a.y - b.y)) for b in labels[i + 1:] if parent.get(b.text) == area]
    return out


def main(argv: list[str]) -> int:
    first, last = (int(argv[0]), int(argv[1])) if len(argv) == 2 else (0, 99)
    by_style: dict[str, list[float]] = defaultdict(list)
    for building in tqdm(parse_world_spec(f"generated:{first}-{last}:signage=complete").generated(),
                         desc="buildings"):
        by_style[building.style] += sibling_distances(building.seed, building.style)
    rows = [("all", [d for ds in by_style.values() for d in ds])] + sorted(by_style.items())
    for name, ds in rows:
        d = np.asarray(ds)
        rms = np.sqrt(np.mean(d ** 2) / 2)
        print(f"{name:9s} pairs {len(d):5d}  median {np.median(d):5.2f} m  per-axis rms {rms:5.2f} m")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
