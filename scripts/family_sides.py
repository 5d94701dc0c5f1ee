"""Which side of the way a label faces its area's other labels hang on: the guided prior's sided family.

Usage: ``python scripts/family_sides.py [FIRST LAST]`` (development seeds, default 64 83). For every ordered
pair of label tags whose places have a parent area (not the building's root), within
``BeliefParams.family_along_m`` along the first label's wall, the share of pairs of one area by how far the
second lies in front of the first (along its facing; negative: behind), for the generated buildings and for
the zoo; then :func:`sim.navigation.belief.across_ratio` over all of a building's labels (what a robot that
had read them all would learn), per building. Seed ``s`` is style ``STYLES[s % 4]``, medium size.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable

import numpy as np
from tqdm import tqdm

from abstract_map.hierarchy import Hierarchy
from sim.experiments.world_spec import parse_world_spec
from sim.navigation.belief import BeliefParams, across_ratio, label_offsets
from sim.world.data import Tag, load_world
from sim.world.generator import generate

BANDS_M = (-15.0, -6.0, -0.5, 0.5, 3.0, 6.0, 15.0)  # m in front of the first label: the table's bins


def area_labels(tags: Iterable[Tag], parent: dict[str, str]) -> list[tuple[Tag, str]]:
    """The label tags whose place has a parent area that is not the root, with that area."""
    return [(t, parent[t.text]) for t in tags if t.kind == "label" and parent.get(t.text) in parent]


def band_counts(labels: list[tuple[Tag, str]], along_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Per band of :data:`BANDS_M`: pairs of one area, and all pairs (two labels of one place not a pair)."""
    ahead, along = label_offsets(np.array([(t.x, t.y) for t, _ in labels]), np.array([t.theta for t, _ in labels]))
    texts = np.array([t.text for t, _ in labels], dtype=object)
    areas = np.array([a for _, a in labels], dtype=object)
    counted = (along <= along_m) & (texts[:, None] != texts[None, :])
    band = np.searchsorted(BANDS_M, ahead, side="right") - 1
    counted &= (band >= 0) & (band < len(BANDS_M) - 1)
    same = areas[:, None] == areas[None, :]
    bins = len(BANDS_M) - 1
    return (np.bincount(band[counted & same], minlength=bins).astype(float),
            np.bincount(band[counted], minlength=bins).astype(float))


def ratio(labels: list[tuple[Tag, str]], params: BeliefParams) -> float:
    return across_ratio(np.array([(t.x, t.y) for t, _ in labels]), np.array([t.theta for t, _ in labels]),
                        [a for _, a in labels], params)


def row(name: str, same: np.ndarray, every: np.ndarray) -> str:
    cells = [f"{s / n:.2f} ({int(n)})" if n else "-" for s, n in zip(same, every)]
    return f"| {name} | " + " | ".join(cells) + " |"


def main(argv: list[str]) -> int:
    first, last = (int(argv[0]), int(argv[1])) if len(argv) == 2 else (64, 83)
    params = BeliefParams()
    heads = [f"{lo:g} to {hi:g} m" for lo, hi in zip(BANDS_M, BANDS_M[1:])]
    print("| buildings | " + " | ".join(heads) + " |")
    print("|---" * (len(heads) + 1) + "|")
    same, every, ratios = np.zeros(len(heads)), np.zeros(len(heads)), []
    for building in tqdm(parse_world_spec(f"generated:{first}-{last}").generated(), desc="buildings"):
        built = generate(building.seed, style=building.style, signage=building.signage)
        labels = area_labels(built.world.tags.values(), built.hierarchy.parent)
        s, e = band_counts(labels, params.family_along_m)
        same, every = same + s, every + e
        ratios.append(ratio(labels, params))
    print(row(f"generated {first}-{last}", same, every))
    zoo = load_world("zoo")
    labels = area_labels(zoo.tags.values(), Hierarchy.from_xml(zoo.hierarchy_path).parent)
    print(row("the zoo", *band_counts(labels, params.family_along_m)))
    print(f"\nacross_ratio over all labels: generated median {np.median(ratios):.2f} "
          f"(range {min(ratios):.2f}-{max(ratios):.2f}), the zoo {ratio(labels, params):.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
