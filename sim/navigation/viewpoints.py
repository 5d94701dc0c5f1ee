"""Readable viewpoints: where to stand so that the goal's label, if it is where the belief says, is read.

The oracle's question ("from where can this label be read?") asked of the
imagined map: the belief over the label's cell (:mod:`sim.navigation.belief`)
is pooled into sites (blocks of ``block_m``), and every reachable block centre
is a candidate viewpoint. A viewpoint's value is the belief mass it would read
(reading range, cone about the wall's normal when the wall is mapped, a clear
sight line over mapped obstacles; unseen space counts as clear), plus a share
of unswept wall near the robot (any wall may carry a sign: cue seeking). The
target is the viewpoint with the most value per metre of travel. World frame,
metres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree
from skimage.graph import MCP_Geometric

from sim.mapping.occupancy import OccupancyGrid, pool_cells, unpool_cells
from sim.navigation.belief import BeliefParams, cell_window, face_normals, in_cone, sight_clear
from sim.navigation.planner import PlannerParams, cost_map


@dataclass(frozen=True)
class ViewpointParams:
    """How viewpoints are valued and chosen."""

    block_m: float = 0.5  # m, belief pooled into sites, and viewpoints spaced, at this block size
    max_sites: int = 150  # sites (blocks) of most mass considered; the rest is a thin tail
    min_site_share: float = 0.01  # sites with less than this share of the heaviest site's mass are dropped
    travel_pool: int = 2  # travel costs are searched on cells this many times coarser (cheapest cell of each)
    unknown_view_prob: float = 0.5  # chance an unseen label faces a viewpoint that has a clear line to it
    site_skip_m: float = 0.09  # m; sight lines stop this short of a site's cell centre (inside its own cell)
    cue_weight: float = 0.1  # value of all unswept wall near the robot (cue seeking) against the goal belief's 1
    cue_radius_m: float = 10.0  # m from the robot within which unswept wall counts for cue seeking
    travel_offset_m: float = 6.0  # m added to travel in the score value / (travel + offset): favours near reads
    keep_ratio: float = 0.75  # keep the current target while its score is at least this share of the best
    visited_radius_m: float = 1.0  # m; a viewpoint reached once is not a target again within this
    escape_cost: float = 20.0  # cost per cell of the impassable band right around the robot (it may be brushing)
    retarget_s: float = 3.0  # s between re-valuing the viewpoints (the belief and map change as it drives)
    sweep_every_s: float = 0.25  # s between marking swept space (the perception looks at 4 Hz)
    exhausted_remaining: float = 0.2  # grow the model when less than this share of the goal's prior is left


@dataclass(frozen=True)
class Viewpoints:
    """Candidate viewpoints and their worth."""

    xy: np.ndarray  # (N, 2) m
    value: np.ndarray  # (N,) belief (+ cue) mass readable there
    travel_m: np.ndarray  # (N,) m along the cheapest path from the robot
    score: np.ndarray  # (N,) value / (travel + offset)

    def best(self) -> int | None:
        if len(self.score) == 0 or float(self.score.max()) <= 0.0:
            return None
        return int(np.argmax(self.score))


def travel_costs(grid: OccupancyGrid, robot_xy: np.ndarray, planner: PlannerParams, escape_cost: float,
                 costs: np.ndarray | None = None, pool: int = 1) -> np.ndarray:
    """Planning cost (m, the planner's cost model; unseen space as cheap as free) from the robot to every cell.

    With ``pool`` > 1 the search runs on blocks of pool x pool cells, each as cheap
    as its cheapest cell (an estimate for valuing targets, not a path)."""
    if costs is None:
        costs = cost_map(grid, planner).costs
    costs = costs.copy()
    rc = grid.world_to_cell(np.asarray(robot_xy, dtype=float))[0]
    rows, cols = grid.shape
    rc = np.clip(rc, 0, [rows - 1, cols - 1])
    reach = int(math.ceil((planner.robot_radius_m + 2 * grid.resolution) / grid.resolution))
    r0, r1, c0, c1 = cell_window(rc, reach, grid.shape)
    occupied = grid.occupied_mask()[r0:r1, c0:c1]
    window = costs[r0:r1, c0:c1]
    window[np.isinf(window) & ~occupied] = escape_cost
    costs[rc[0], rc[1]] = min(costs[rc[0], rc[1]], escape_cost)
    if pool <= 1:
        cumulative, _ = MCP_Geometric(costs, fully_connected=True).find_costs([tuple(rc)])
        return cumulative * grid.resolution
    coarse = pool_cells(costs, pool, np.inf, np.min)
    cumulative, _ = MCP_Geometric(coarse, fully_connected=True).find_costs([tuple(rc // pool)])
    return unpool_cells(cumulative, pool, grid.shape) * grid.resolution * pool


@dataclass(frozen=True)
class Sites:
    """Belief pooled into blocks (K of them)."""

    xy: np.ndarray  # (K, 2) m, mass-weighted centre
    mass: np.ndarray  # (K,)
    wall: np.ndarray  # (K,) share of the mass on mapped wall
    axis: np.ndarray  # (K,) rad, unsigned wall-normal angle
    coherence: np.ndarray  # (K,) of that axis
    normal: np.ndarray  # (K, 2) mean face normal (to the free side)
    sided: np.ndarray  # (K,) how one-sided the wall is (>= 0.5: only its front reads)


def pool_sites(grid: OccupancyGrid, mass: np.ndarray, block_cells: int, max_sites: int, smoothing_cells: float,
               min_share: float = 0.0) -> Sites:
    """The ``max_sites`` blocks of most mass (and at least ``min_share`` of the heaviest's)."""
    rows, cols = mass.shape
    b = block_cells
    pr, pc = -(-rows // b) * b, -(-cols // b) * b
    occupied = grid.occupied_mask()
    nx, ny, sided, angle, coherence = face_normals(occupied, smoothing_cells)
    padded = np.zeros((pr, pc), dtype=np.float64)
    padded[:rows, :cols] = mass
    blocks = padded.reshape(pr // b, b, pc // b, b).transpose(0, 2, 1, 3).reshape(pr // b, pc // b, b * b)
    m = blocks.sum(axis=2)
    keep = np.argwhere(m > 0)
    if len(keep) == 0:
        empty = np.zeros(0)
        return Sites(np.zeros((0, 2)), empty, empty, empty, empty, np.zeros((0, 2)), empty)
    kept = m[keep[:, 0], keep[:, 1]]
    order = np.argsort(-kept)[:max_sites]
    keep = keep[order][kept[order] >= min_share * kept.max()]
    # Each site stands at its block's heaviest cell, with that cell's wall geometry.
    k = np.argmax(blocks[keep[:, 0], keep[:, 1]], axis=1)
    r = np.minimum(keep[:, 0] * b + k // b, rows - 1)
    c = np.minimum(keep[:, 1] * b + k % b, cols - 1)
    xy = grid.cell_to_world(np.stack([r, c], axis=1))
    wall = occupied[r, c].astype(float)
    return Sites(xy, m[keep[:, 0], keep[:, 1]], wall, angle[r, c], coherence[r, c],
                 np.stack([nx[r, c], ny[r, c]], axis=1), sided[r, c])


def score_viewpoints(grid: OccupancyGrid, travel_m: np.ndarray, site_mass: np.ndarray, params: ViewpointParams,
                     belief: BeliefParams, visited: list[np.ndarray] | tuple = ()) -> Viewpoints:
    """Every reachable block centre, valued by the site mass (per grid cell, any scale) readable from it."""
    res = grid.resolution
    b = max(1, round(params.block_m / res))
    sites = pool_sites(grid, site_mass, b, params.max_sites, belief.normal_smoothing_m / res, params.min_site_share)
    xy_s, mass_s, wall_s = sites.xy, sites.mass, sites.wall
    rows, cols = grid.shape
    centres = np.argwhere(np.ones((-(-rows // b), -(-cols // b)), dtype=bool)) * b + b // 2
    centres = centres[(centres[:, 0] < rows) & (centres[:, 1] < cols)]
    reach = travel_m[centres[:, 0], centres[:, 1]]
    centres, reach = centres[np.isfinite(reach)], reach[np.isfinite(reach)]
    xy_v = grid.cell_to_world(centres)
    value = np.zeros(len(xy_v))
    if len(xy_v) and len(xy_s):
        tree = cKDTree(xy_v)
        pairs = [(i, j) for i, near in enumerate(tree.query_ball_point(xy_s, belief.read_range_m)) for j in near]
        if pairs:
            site, view = np.array(pairs).T
            d = np.hypot(*(xy_v[view] - xy_s[site]).T)
            ok = d >= belief.read_min_m
            site, view = site[ok], view[ok]
            cone = in_cone(xy_s[site], xy_v[view], sites.axis[site], sites.coherence[site], belief,
                           sites.normal[site], sites.sided[site])
            factor = wall_s[site] * cone + (1.0 - wall_s[site]) * params.unknown_view_prob
            live = factor > 0
            site, view, factor = site[live], view[live], factor[live]
            clear = _clear_pairs(grid, xy_v[view], xy_s[site], params.site_skip_m)
            np.add.at(value, view[clear], mass_s[site[clear]] * factor[clear])
    for point in visited:
        value[np.hypot(*(xy_v - point).T) < params.visited_radius_m] = 0.0
    score = value / (reach + params.travel_offset_m)
    return Viewpoints(xy_v, value, reach, score)


def _clear_pairs(grid: OccupancyGrid, origins: np.ndarray, ends: np.ndarray, skip_m: float,
                 chunk: int = 20000) -> np.ndarray:
    """Clear sight lines (over mapped obstacles only) for many origin-end pairs, in chunks."""
    occupied = grid.occupied_mask()
    out = np.zeros(len(origins), dtype=bool)
    for k in range(0, len(origins), chunk):
        out[k:k + chunk] = sight_clear(occupied, grid, origins[k:k + chunk], ends[k:k + chunk], skip_m, 1.0)
    return out
