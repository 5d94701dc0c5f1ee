"""Where the label of a place named by an arrow hangs, in the arrow's own frame: what an arrow says of a place.

Usage: ``python scripts/arrow_spread.py [FIRST LAST]`` (development seeds, default 0 99) or
``python scripts/arrow_spread.py --world NAME`` (a world folder or a name under ``worlds/``, e.g. ``zoo``).

For every arrow line of every sign and every place it names whose label the world holds, the label's offset
from the sign (m) split along the arrow and across it. Prints, per style (generated) or for the world, the
median and standard deviation along, the rms and median size across, and the rms miss of a place put
``length`` m along the arrow (``--length``, default 8 m: where the spring model's arrow spring holds a place
at the sign scale of level 1; ``docs/method-notes.md``, "What the imagined goal is worth"). The seeds are
``generated:FIRST-LAST:signage=complete`` (style cycling with the seed, medium size; every arrow to a goal,
and the layout does not depend on the signage).
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterable

import numpy as np

from abstract_map.clauses import Locational
from sim.experiments.survey import buildings, on_world, survey_parser
from sim.world.data import Tag, World
from sim.world.generator import generate


def arrow_offsets(tags: Iterable[Tag]) -> list[tuple[float, float]]:
    """(along, across) m of each named place's label from the sign whose arrow names it, in the arrow's frame
    (across: positive to the arrow's left). Places without a label are left out."""
    tags = list(tags)
    labels = {t.text.casefold(): t for t in tags if t.kind == "label"}
    out = []
    for sign in (t for t in tags if t.kind == "sign"):
        for clause in sign.clauses():
            if not isinstance(clause, Locational) or clause.kind != "arrow":
                continue
            label = labels.get(clause.toponym.casefold())
            if label is None:
                continue
            dx, dy = label.x - sign.x, label.y - sign.y
            c, s = math.cos(clause.direction), math.sin(clause.direction)
            out.append((dx * c + dy * s, -dx * s + dy * c))
    return out


def summary(name: str, offsets: list[tuple[float, float]], length_m: float) -> str:
    """One line: how many arrows, and the spread along and across them (m)."""
    if not offsets:
        return f"{name:9s} no arrow names a labelled place"
    along, across = np.asarray(offsets).T
    miss = np.sqrt(np.mean((along - length_m) ** 2 + across ** 2))
    return (f"{name:9s} arrows {len(along):5d}  along: median {np.median(along):5.1f} m, sd {along.std():5.1f} m  "
            f"across: rms {np.sqrt(np.mean(across ** 2)):5.1f} m, median size {np.median(abs(across)):5.1f} m  "
            f"miss of a place {length_m:g} m along: rms {miss:5.1f} m")


def world_offsets(world: World) -> list[tuple[float, float]]:
    return arrow_offsets(world.tags.values())


def main(argv: list[str] | None = None) -> int:
    parser = survey_parser(__doc__, (0, 99))
    parser.add_argument("--length", type=float, default=8.0, help="m along the arrow a place is put (default 8)")
    args = parser.parse_args(argv)
    if args.world:
        print(summary(args.world, on_world(parser, args, "arrow_spread", world_offsets), args.length))
        return 0
    by_style: dict[str, list[tuple[float, float]]] = defaultdict(list)
    for building in buildings(parser, args, ":signage=complete"):
        by_style[building.style] += world_offsets(generate(building.seed, style=building.style).world)
    print(summary("all", [o for os_ in by_style.values() for o in os_], args.length))
    for style, offsets in sorted(by_style.items()):
        print(summary(style, offsets, args.length))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
