"""How often a sign carries the fingerpost test's mark: an arrow pointing back into a wall beside its reader.

Usage: ``python scripts/fingerpost_marks.py [FIRST LAST]`` (development seeds, default 0 11) or
``python scripts/fingerpost_marks.py --world NAME`` (a world folder or a name under ``worlds/``, e.g. ``zoo``).

Every development seed is built in every style (``sim.world.styles.STYLES``) with complete signage, twice: its
signs written as wayfinding signs (``arrows=way``, the route's first leg) and as fingerposts (``arrows=bearing``,
the place's bearing); the plan, labels and sign positions are the same building's. Each sign with an arrow is
judged as the guided search judges it (:func:`sim.navigation.fingerposts.runs_into_wall` with the default
:class:`~sim.navigation.fingerposts.PostParams`), on the building's true plan mapped whole at the plan's own
resolution (:func:`sim.mapping.occupancy.mapped_plan`: a zoo wall two centimetres thick is mapped). Prints, per
style and reading, the share of signs with the mark, then the shares over every style: what
``PostParams.blocked_post`` and ``blocked_way`` stand for, and the likelihood ratios a sign with and without the
mark gives the odds that a building's arrows are fingerposts.
"""

from __future__ import annotations

import math
from collections import Counter

from tqdm import tqdm

from abstract_map.clauses import Locational
from sim.experiments.survey import on_world, seed_range, survey_parser
from sim.mapping.occupancy import mapped_plan
from sim.navigation.fingerposts import PostParams, runs_into_wall
from sim.world.data import World
from sim.world.generator import generate
from sim.world.styles import STYLES
from sim.world.truth import ARROW_READINGS


def marks(world: World, params: PostParams | None = None) -> Counter[bool]:
    """Whether each sign of ``world`` with an arrow has the mark (by ``params``, default :class:`PostParams`)
    -> how many signs."""
    params = params or PostParams()
    grid = mapped_plan(world.floorplan, world.floorplan.resolution)
    out: Counter[bool] = Counter()
    for sign in (t for t in world.tags.values() if t.kind == "sign"):
        directions = [c.direction for c in sign.clauses() if isinstance(c, Locational) and c.kind == "arrow"]
        if directions:
            out[any(runs_into_wall(grid, (sign.x, sign.y), sign.theta, d, params) for d in directions)] += 1
    return out


def line(name: str, counts: Counter[bool]) -> str:
    """One line: how many signs, how many with the mark, and that share."""
    signs = counts[True] + counts[False]
    share = counts[True] / signs if signs else math.nan
    return f"{name:20s} signs {signs:5d}  with the mark {counts[True]:5d}  share {share:.3f}"


def main(argv: list[str] | None = None) -> int:
    parser = survey_parser(__doc__, (0, 11))
    args = parser.parse_args(argv)
    if args.world:
        print(line(args.world, on_world(parser, args, "fingerpost_marks", marks)))
        return 0
    first, last = seed_range(parser, args)
    totals: dict[str, Counter[bool]] = {reading: Counter() for reading in ARROW_READINGS}
    lines = []
    with tqdm(total=len(ARROW_READINGS) * len(STYLES) * (last - first + 1), desc="buildings") as bar:
        for reading in ARROW_READINGS:
            for style in STYLES:
                counts: Counter[bool] = Counter()
                for seed in range(first, last + 1):
                    counts += marks(generate(seed, style=style, signage="complete", arrows=reading).world)
                    bar.update()
                totals[reading] += counts
                lines.append(line(f"{style}, {reading}", counts))
    lines += [line(f"all, {reading}", counts) for reading, counts in totals.items()]
    post, way = (totals[r][True] / max(1, totals[r][True] + totals[r][False]) for r in ("bearing", "way"))
    if 0 < way and post < 1:
        lines.append(f"likelihood ratio: a sign with the mark {post / way:.1f}, "
                     f"without {(1 - post) / (1 - way):.3f}")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
