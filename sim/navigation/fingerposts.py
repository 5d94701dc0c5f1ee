"""Whether a building's arrows point at their places (fingerposts) or the way to set off (wayfinding signs).

The abstract map reads an arrow as the paper does: the direction of its place,
with a distance on it. That holds for fingerposts (a zoo's, a park's), and the
imagined goal is then worth following. A building's wayfinding signs point
the way to set off instead, the route's first leg, and there the imagined goal
lies farther from the label than a point drawn anywhere on the floor
(``docs/method-notes.md``, "Trust in the model's point earned inside the
building"). The two kinds differ where the robot can see it at the first sign:
a way sets off over free floor, so a wayfinding arrow runs clear of walls from
its reader, while a fingerpost points through whatever lies between, often
back through the wall the sign hangs on. So a sign with an arrow pointing
back (one of the three of eight arrow directions more than 120 degrees off
the sign's face: DOWN and its diagonals) that meets a wall within
``reach_m`` of the reader is the mark of a fingerpost. (An arrow pointing
ahead that meets a wall says nothing: across a narrow corridor the far wall
is that near, and a way sets off across it into a side corridor or a door.)

Measured on the generator's buildings (``python scripts/fingerpost_marks.py``:
development seeds 0-11, every style, complete signage, the true plans;
``arrows=way`` and ``arrows=bearing`` of the same buildings; the reader 1 m in
front of the sign, a wall within 1.5 m along the arrow): 80 % of fingerpost
signs have such an arrow (72-88 % by style), 7.7 % of wayfinding signs (3-15 %;
a first leg setting off back along the wall can round to DOWN). Counting any
arrow that meets a wall, ahead too, gave 84 % against 13 %: a likelihood ratio
of 6.5 where this one gives 10.4. Each sign read is one observation, weighed
by Bayes' rule on the odds that the building's arrows are fingerposts
(:class:`PostTest`); a sign is judged once, on the robot's map when it is
first counted (unseen cells count as clear). The guided search gives that
chance of the goal's prior to the abstract map's point and of each arrow's
likelihood to its bearing (``routes.route_likelihood``'s ``bearing_share``),
the rest to the even prior and the route's first leg.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from sim.mapping.occupancy import OccupancyGrid


@dataclass(frozen=True)
class PostParams:
    """The fingerpost test's odds (:mod:`sim.navigation.fingerposts`)."""

    prior: float = 0.5  # chance the building's arrows are fingerposts before a sign is read: nothing says which;
    # 1 keeps the paper's reading whatever the signs show
    blocked_post: float = 0.80  # share of fingerpost signs with an arrow pointing back into a wall within
    # ``reach_m`` of the reader (module docstring: development seeds 0-11, every style)
    blocked_way: float = 0.077  # the same share for wayfinding signs
    stand_m: float = 1.0  # m in front of the sign where its reader stands (the signage convention's reader,
    # ``RouteParams.stand_m``)
    reach_m: float = 1.5  # m along an arrow from the reader that a way must run clear: ``RouteParams.lead_m``,
    # where a route's first leg is read off
    step_m: float = 0.05  # m between the points tested along the arrow (a quarter of a 0.2 m grid cell or less)
    back_deg: float = 120.0  # deg off the sign's face beyond which an arrow points back: DOWN and its two diagonal
    # neighbours, the three of the eight arrow directions that point into the sign's own wall


def runs_into_wall(grid: OccupancyGrid, sign_xy: tuple[float, float], facing: float, direction: float,
                   params: PostParams) -> bool:
    """Whether an arrow (``direction``, rad, world frame) of a sign at ``sign_xy`` (m) facing ``facing`` (rad)
    points back (more than ``back_deg`` off the sign's face) and meets a mapped wall within ``reach_m`` of the
    sign's reader."""
    if abs(math.degrees(math.remainder(direction - facing, math.tau))) <= params.back_deg:
        return False
    reader = np.asarray(sign_xy, dtype=float) + params.stand_m * np.array([math.cos(facing), math.sin(facing)])
    along = np.arange(params.step_m, params.reach_m + params.step_m / 2, params.step_m)
    points = reader + along[:, None] * np.array([math.cos(direction), math.sin(direction)])
    return bool(grid.occupied_cells(grid.world_to_cell(points)).any())


@dataclass
class PostTest:
    """The chance that this building's arrows are fingerposts, from the signs read so far."""

    params: PostParams = field(default_factory=PostParams)
    judged: dict[str, bool] = field(default_factory=dict)  # sign anchor -> an arrow of it points back into a wall

    def judge(self, grid: OccupancyGrid, signs: Iterable[tuple[str, tuple[float, float], float, list[float]]]) -> None:
        """Judge each sign not yet judged: (anchor, position m, facing rad, its arrows' directions rad)."""
        for anchor, xy, facing, directions in signs:
            if anchor not in self.judged and directions:
                self.judged[anchor] = any(runs_into_wall(grid, xy, facing, d, self.params) for d in directions)

    @property
    def chance(self) -> float:
        """P(fingerposts | the signs judged), by Bayes' rule on the odds (``prior`` 0 or 1 stays put)."""
        p = self.params
        if p.prior <= 0.0 or p.prior >= 1.0:
            return float(min(max(p.prior, 0.0), 1.0))
        log_odds = math.log(p.prior / (1.0 - p.prior))
        for blocked in self.judged.values():
            log_odds += math.log(p.blocked_post / p.blocked_way) if blocked else \
                math.log((1.0 - p.blocked_post) / (1.0 - p.blocked_way))
        return 1.0 / (1.0 + math.exp(-log_odds))
