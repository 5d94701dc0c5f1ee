"""What lies behind each frontier: belief mass gathered by the frontier its route enters through.

A frontier is where space looked at meets space not yet looked at. The goal's
label may hang anywhere not yet looked at, weighted by a belief ``b`` (per
grid cell, :class:`sim.navigation.policies.GuidedPolicy`). The robot would
reach a place ``x`` by its shortest route over its own map (mapped walls
block, unseen space is open), and that route enters space not yet looked at
at one cell, its *gateway* ``g(x)``. A frontier cell ``f`` is worth the mass
whose gateway lies within ``gather_m`` of it:

    V(f) = sum over x with |g(x) - f| <= gather_m of b(x)

So the open end of a corridor carries everything the corridor leads to, and a
room's doorway only the room. But the robot is looking for one label and pays
for every metre it walks: the search drives to the frontier of least
``(path + offset) / V`` (belief per metre), and all a corridor leads to is
worth that much only once the robot has walked to the far end of it. So a
frontier's worth is the best rate that walking on past it for some distance
``k`` (``GuideParams.look_ahead_m``) would give:

    V(f) = max over k of M_f(k) (p_f + o) / (p_f + o + k)

with ``M_f(k)`` the mass gathered by ``f`` whose route goes at most ``k`` past
its gateway, ``p_f`` the route from the robot to the gateway and ``o`` the
offset: ``(p_f + o) / V(f)`` is then the least metres per unit of belief over
those walks (a Gittins-style index for one branch of the search), so a plate
in front of the robot is not outweighed by the sum of all the rooms a corridor
leads to. Mass on a mapped wall cell (where labels hang)
counts at the wall's neighbouring cell that the robot reaches first. World
frame, metres; routes are searched on cells of ``RouteParams.cell_m``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from sim.mapping.occupancy import OccupancyGrid, pool_cells, unpool_cells
from sim.navigation.fingerposts import PostParams
from sim.navigation.routes import PathSearches, RouteParams, follow_pointers, open_cell, route_cells

WALL_CELLS = 1e4  # route cost of a wall cell, in open cells: more than any route through open space


@dataclass(frozen=True)
class GuideParams:
    """How the guided search values frontiers (``--navigator guided``)."""

    gather_m: float = 0.9  # m; a frontier cell lies within the robot's reach (0.3 m) plus a door's half width
    # of the unlooked-at cells its space opens onto, so a doorway's frontier gathers the whole doorway
    looked_share: float = 0.5  # share of a route cell's fine cells looked at for it to count as looked at
    offset_m: float = 3.0  # m added to a frontier's path before dividing by its value: what must be walked past
    # it to look behind it (the look radius), so a frontier at the robot's feet is not worth without bound
    floor: float = 1e-6  # a value below this share of the best counts as this (nowhere is ruled out)
    rechoose_s: float = 5.0  # s between choosing the frontier afresh (the evidence changes as the map grows)
    exhausted_remaining: float = 0.5  # grow the abstract map (one exploration step) while less than this share of
    # the goal's prior is left unswept: the label is not where the model imagines it. Development buildings 24-63:
    # at the viewpoint search's 0.2 it never grew within 600 s (the tail keeps the unseen building), at 0.65 it
    # lost, at 0.5 it gained (docs/method-notes.md, "The abstract map grown by the space looked at")
    min_target_m: float = 1.0  # m; frontiers nearer than this by path are skipped (the robot sees them as it goes)
    look_ahead_m: tuple[float, ...] = (0.0, 3.0, 6.0, 12.0, 24.0, 48.0, 96.0)  # m walked past a frontier over which
    # its worth is the best rate of belief per metre (module docstring): doubling steps from one look (3 m) to
    # about a building's span; empty: a frontier is worth all the mass behind it, however far
    even_spread_m: float = 1000.0  # m, the ``even-prior`` ablation's floor on the goal prior's spread, for every
    # way the cues name the goal (``BeliefParams.floor_m``): far beyond any building, so the prior lies even over
    # the map (the model's misses average it down slowly: to about 300 m after 30 labels read) until labels of the
    # goal's siblings are read, which then hold it
    posts: PostParams = PostParams()  # the fingerpost test (sim/navigation/fingerposts.py): its chance is the share
    # of the goal's prior the model's point holds (the rest lies as ``even-prior``'s does) and of each arrow's
    # likelihood its bearing's (the rest its route's); ``PostParams(prior=1.0)`` is the paper's reading throughout
    known_front_m: float = 1.5  # m in front of the goal's label the ``known-pose`` reference drives to: past the
    # camera's 1 m near limit and well inside the 4 m reading range
    known_spread_m: float = 1.0  # m, the ``known-goal`` baseline's prior about the goal's true label: the label to
    # within the wall and door beside it; 5 m gave the same walks (complete-signage development goals, SPL 0.800
    # against 0.803; docs/method-notes.md, "The ceiling of a known goal")


def frontier_values(grid: OccupancyGrid, mass: np.ndarray, looked: np.ndarray, robot_xy: np.ndarray,
                    params: GuideParams = GuideParams(), routes: RouteParams | None = None) -> np.ndarray:
    """Per cell of ``grid``, the belief mass ``V`` (same units as ``mass``) whose route from ``robot_xy`` (m)
    enters space not yet ``looked`` at within ``gather_m`` of that cell.

    ``mass`` and ``looked`` have the grid's shape. Mass the robot cannot reach over its map (cut off, beyond a
    wall, or deeper in one than three route cells) is in no frontier's value.
    """
    routes = RouteParams() if routes is None else routes
    pool, blocked = route_cells(grid, routes)
    step = pool * grid.resolution
    coarse = pool_cells(np.asarray(mass, dtype=float), pool, 0.0, np.sum)
    unlooked = pool_cells(looked.astype(np.float32), pool, np.float32(0.0), np.mean) < params.looked_share
    start = open_cell(grid, pool, blocked, np.asarray(robot_xy, dtype=float))
    if start is None:
        return np.zeros(grid.shape)
    # Walls cost WALL_CELLS per cell, so a wall cell is reached from its open side nearest the robot by route
    # (the side a label there is read from) while no route through open space crosses one.
    lengths, pred = PathSearches().tree("robot", np.where(blocked, WALL_CELLS, 1.0), start)
    counted = np.where(blocked, lengths < 3 * WALL_CELLS, lengths < WALL_CELLS)  # a wall's face, not beyond it
    carried = np.where(counted, coarse, 0.0).ravel()
    # Each cell's gateway: the first cell on its route not yet looked at (a looked-at cell is its own).
    flat_unlooked = unlooked.ravel()
    own = np.arange(coarse.size)
    gateway = follow_pointers(np.where(flat_unlooked & flat_unlooked[pred], pred, own))
    value = _worth(carried, gateway, lengths, pred, blocked, step, params).reshape(blocked.shape)
    reach = max(0, int(round(params.gather_m / step)))
    gathered = ndimage.uniform_filter(value, size=2 * reach + 1, mode="constant") * (2 * reach + 1) ** 2
    return unpool_cells(np.maximum(gathered, 0.0), pool, grid.shape)


def _worth(carried: np.ndarray, gateway: np.ndarray, lengths: np.ndarray, pred: np.ndarray, blocked: np.ndarray,
           step: float, params: GuideParams) -> np.ndarray:
    """Per route cell (flat), what the mass ``carried`` by the cells whose ``gateway`` it is is worth: all of it
    with no ``look_ahead_m``, else the best rate over walks of each ``k`` past it (module docstring).
    ``lengths``, ``pred``: the search from the robot (route cells; walls cost ``WALL_CELLS``); ``step``: m per
    route cell."""
    if not params.look_ahead_m:
        return np.bincount(gateway, carried, minlength=carried.size)
    own = np.arange(carried.size)
    opened = follow_pointers(np.where(blocked.ravel(), pred, own))  # a wall cell's open cell, where it is read
    walked = lengths.ravel()[opened]
    walked = np.where(np.isfinite(walked), walked, 0.0) * step  # m from the robot (a wall's: to its face)
    lead = walked + params.offset_m  # m, p_f + o at each gateway
    past = np.maximum(walked - walked[gateway], 0.0)  # m walked past a cell's gateway to reach it
    best = np.zeros(carried.size)
    for k in params.look_ahead_m:
        within = np.bincount(gateway, np.where(past <= k, carried, 0.0), minlength=carried.size)
        best = np.maximum(best, within * lead / (lead + k))
    return best
