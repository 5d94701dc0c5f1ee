"""The oracle: the shortest path any navigator starting at the start could take to read a goal.

On the full floor plan, obstacles inflated by the robot's radius, the oracle
searches (scikit-image's minimum-cost-path, 8-connected, exact diagonal
lengths) from the start to the nearest cell from which the goal's label can be
read: within the reading range, inside the visibility cone about the tag's
normal, and with a clear line of sight. Its length is the physical lower
bound of a trial's distance (up to the grid's resolution).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from skimage.graph import MCP_Geometric

from sim.world.data import Floorplan, Tag, World
from sim.world.visibility import readable


@dataclass(frozen=True)
class OracleParams:
    """What "can read the tag" means, and the grid the oracle searches."""

    cell_m: float = 0.05  # m, search grid (the floor plan is max-pooled to about this)
    robot_radius_m: float = 0.38  # m, obstacles inflated by this (the planner's radius)
    read_range_m: float = 4.0  # m from the tag
    cone_half_angle_deg: float = 45.0  # deg about the tag's normal


@dataclass(frozen=True)
class OraclePath:
    goal: str
    tag_id: int
    length_m: float
    path: np.ndarray  # (N, 2) m, world frame, start to reading pose


def pooled_floorplan(world: World, cell_m: float) -> Floorplan:
    """The world's floor plan max-pooled to cells of about ``cell_m`` (m); the origin is unchanged."""
    return pool_plan(world.floorplan, cell_m)


def pool_plan(plan: Floorplan, cell_m: float) -> Floorplan:
    """``plan`` max-pooled to cells of about ``cell_m`` (m); the origin is unchanged."""
    factor = max(1, round(cell_m / plan.resolution))
    occ = plan.occupied
    rows, cols = (occ.shape[0] // factor) * factor, (occ.shape[1] // factor) * factor
    occ = occ[occ.shape[0] - rows:, :cols]  # crop from the top, keeping the bottom-left origin
    pooled = occ.reshape(rows // factor, factor, cols // factor, factor).any(axis=(1, 3))
    return Floorplan(pooled, plan.resolution * factor, plan.origin)


def readable_cells(plan: Floorplan, tag: Tag, params: OracleParams) -> np.ndarray:
    """Boolean mask over ``plan`` of cells from which ``tag`` can be read (range, cone, line of sight)."""
    occupied, res = plan.occupied, plan.resolution
    rows, cols = occupied.shape
    r = int(math.ceil(params.read_range_m / res))
    centre = plan.world_to_pixel(np.array([tag.x, tag.y]))[0]
    r0, r1 = max(0, centre[0] - r), min(rows, centre[0] + r + 1)
    c0, c1 = max(0, centre[1] - r), min(cols, centre[1] + r + 1)
    rr, cc = np.mgrid[r0:r1, c0:c1]
    xy = plan.pixel_to_world(np.stack([rr.ravel(), cc.ravel()], axis=1)).reshape(*rr.shape, 2)
    ok = readable(xy[..., 0], xy[..., 1], tag.x, tag.y, tag.theta, max_range_m=params.read_range_m,
                  cone_half_angle_deg=params.cone_half_angle_deg)
    normal = np.array([math.cos(tag.theta), math.sin(tag.theta)])
    cand = np.argwhere(ok)
    mask = np.zeros_like(occupied)
    if len(cand) == 0:
        return mask
    # Line of sight: sample each segment from the first free cell in front of the tag (tags hang on,
    # and are drawn inside, their own wall) to the candidate cell.
    front = np.array([tag.x, tag.y])
    for step in np.arange(0.0, 0.5, 0.5 * res):
        ahead = plan.world_to_pixel(front + step * normal)[0]
        if 0 <= ahead[0] < rows and 0 <= ahead[1] < cols and not occupied[ahead[0], ahead[1]]:
            front = front + step * normal
            break
    ends = xy[cand[:, 0], cand[:, 1]]
    n = int(math.ceil(params.read_range_m / (0.5 * res))) + 1
    s = np.linspace(0.0, 1.0, n)[None, :, None]
    pts = front[None, None, :] + s * (ends[:, None, :] - front[None, None, :])
    prc = plan.world_to_pixel(pts.reshape(-1, 2)).reshape(*pts.shape[:2], 2)
    prc[..., 0] = np.clip(prc[..., 0], 0, rows - 1)
    prc[..., 1] = np.clip(prc[..., 1], 0, cols - 1)
    clear = ~occupied[prc[..., 0], prc[..., 1]].any(axis=1)
    good = cand[clear]
    mask[good[:, 0] + r0, good[:, 1] + c0] = True
    return mask


def free_cells(plan: Floorplan, robot_radius_m: float) -> np.ndarray:
    """Boolean mask over ``plan`` of cells where the robot's centre fits: farther than its radius from any wall."""
    return ndimage.distance_transform_edt(~plan.occupied) * plan.resolution > robot_radius_m


def distance_field(free: np.ndarray, sources: list[tuple[int, int]]) -> tuple[np.ndarray, MCP_Geometric]:
    """Shortest 8-connected path lengths (cells, exact diagonals) over ``free`` from the nearest of ``sources``.

    Returns the cumulative cost (inf where unreachable) and the searcher,
    whose ``traceback(cell)`` gives the path from the nearest source to ``cell``.
    """
    mcp = MCP_Geometric(np.where(free, 1.0, np.inf))
    cumulative, _ = mcp.find_costs(sources)
    return cumulative, mcp


def nearest_cell(cumulative: np.ndarray, mask: np.ndarray) -> tuple[float, tuple[int, int]] | None:
    """The cheapest reachable cell of ``mask`` and its cost (cells), or None when none is reachable."""
    cells = np.argwhere(mask)
    if len(cells) == 0:
        return None
    costs = cumulative[cells[:, 0], cells[:, 1]]
    i = int(np.argmin(costs))
    if not np.isfinite(costs[i]):
        return None
    return float(costs[i]), (int(cells[i, 0]), int(cells[i, 1]))


def oracle_path(world: World, goal: str, start: tuple[float, float] | None = None,
                params: OracleParams | None = None) -> OraclePath:
    """Shortest path from ``start`` (default: the world's start) to read ``goal``'s label."""
    return oracle_paths(world, [goal], start, params)[goal]


def oracle_paths(world: World, goals: list[str], start: tuple[float, float] | None = None,
                 params: OracleParams | None = None) -> dict[str, OraclePath]:
    """:func:`oracle_path` for several goals, searching the floor plan once."""
    params = params or OracleParams()
    for goal in goals:
        if not world.label_tags(goal):
            raise ValueError(f"goal {goal!r}: no label tag in world {world.name!r}")
    grid = pooled_floorplan(world, params.cell_m)
    free = free_cells(grid, params.robot_radius_m)
    start_xy = np.array(start if start is not None else world.start[:2], dtype=float)
    start_rc = tuple(grid.world_to_pixel(start_xy)[0])
    if not free[start_rc]:
        raise ValueError(f"oracle: the start {tuple(start_xy)} is within the robot's radius of a wall")
    cumulative, mcp = distance_field(free, [start_rc])
    paths: dict[str, OraclePath] = {}
    for goal in goals:
        best: tuple[float, Tag, tuple[int, int]] | None = None
        for tag in world.label_tags(goal):
            found = nearest_cell(cumulative, readable_cells(grid, tag, params) & free)
            if found is not None and (best is None or found[0] < best[0]):
                best = (found[0], tag, found[1])
        if best is None:
            raise ValueError(f"oracle: no reachable pose reads the label of {goal!r}")
        _, tag, end = best
        path = grid.pixel_to_world(np.array(mcp.traceback(end)))
        length = float(np.hypot(*np.diff(path, axis=0).T).sum())
        paths[goal] = OraclePath(goal, tag.id, length, path)
    return paths
