"""Frontiers: where seen free space meets unseen space, and the nearest one by path length.

Frames: world frame, metres. A frontier cell is a cell the robot can stand in
(seen free, more than its radius from any seen obstacle) within
``FrontierParams.reach_m`` of unseen space. The laser sees 8 m but a label is
read only within 4 m, so a searcher for labels counts space as seen only once
it was *looked at*: known on the occupancy grid and within ``look_radius_m``
in line of sight of the robot (:func:`look`, a ``covered`` mask); without that
mask, unseen means unknown on the occupancy grid. Frontier cells are grouped
8-connected and groups smaller than ``min_size_m`` (specks between laser
beams) are dropped. Distances are path lengths through passable seen space
(scikit-image's minimum-cost path, 8-connected), never straight lines.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy import ndimage
from skimage.graph import MCP_Geometric

from sim.mapping.occupancy import OccupancyGrid
from sim.navigation.planner import clearance_m
from sim.navigation.targeting import filled_free, seen_passable

_EIGHT = np.ones((3, 3), dtype=bool)


@dataclass(frozen=True)
class FrontierParams:
    """What counts as a frontier and when a frontier target is done with."""

    reach_m: float = 0.3  # m; a standing cell this close to unseen space is on the frontier (a door's middle
    # lies more than the robot's radius from its jambs, so the unseen room beyond is ~0.3 m from it)
    min_size_m: float = 0.5  # m, smallest frontier worth a visit: narrower gaps are specks between beams
    fill_holes_cells: int = 2  # closing iterations that fill unseen specks between beams (as the targeting's)
    min_distance_m: float = 1.0  # m; frontiers nearer than this by path are skipped (the laser sees them now)
    visited_radius_m: float = 1.5  # m around a frontier target reached (or found unreachable) never chosen again
    recheck_s: float = 2.0  # s between checks that the current target is still on a frontier
    snap_m: float = 1.0  # m; a robot brushing a wall starts its search from the nearest standing cell this close
    # m; cells this close in line of sight count as looked at: inside the 4 m reading range (geometric
    # perception, the oracle), with a margin for labels seen off their normal
    look_radius_m: float = 3.0
    look_every_m: float = 0.1  # m the robot moves between looks (a look is all round; the map grows in between)
    look_rays: int = 180  # rays cast over the grid for :func:`look` (2 degrees apart: 10 cm apart at 3 m)


@dataclass(frozen=True)
class Frontiers:
    """Frontier cells of a grid and their path distance from the robot."""

    mask: np.ndarray  # (rows, cols) bool: frontier cells (in groups of at least min_size_m)
    distance_m: np.ndarray  # (rows, cols) float: path length from the robot through passable seen space; inf


def look(grid: OccupancyGrid, covered: np.ndarray, robot_xy: np.ndarray, params: FrontierParams,
         rays: np.ndarray | None = None) -> None:
    """Mark in ``covered`` (bool, the grid's shape) the known cells within ``look_radius_m`` of ``robot_xy`` (m)
    in line of sight over the grid (a ray stops at the first occupied cell, which it marks); ``rays``:
    :func:`look_rays` for this grid when already at hand."""
    offsets = look_rays(grid, params) if rays is None else rays
    shape = offsets.shape[1:]  # (rays, samples)
    rc = grid.world_to_cell(np.asarray(robot_xy, dtype=float)[:2] + offsets.reshape(2, -1).T)
    inside = grid.in_bounds(rc).reshape(shape)
    row, col = rc[:, 0].reshape(shape), rc[:, 1].reshape(shape)
    values = np.zeros(shape, dtype=np.float32)  # outside the grid: unknown
    values[inside] = grid.log_odds[row[inside], col[inside]]
    occupied = values > grid.params.occupied_threshold
    known = occupied | (values < grid.params.free_threshold)
    # visible: no occupied sample before this one along the ray (the first occupied one is visible)
    blocked_before = np.cumsum(occupied, axis=1) - occupied > 0
    mark = ~blocked_before & inside & known
    covered[row[mark], col[mark]] = True


def look_rays(grid: OccupancyGrid, params: FrontierParams) -> np.ndarray:
    """(2, rays, samples): the x and y offsets (m) from the robot of the samples :func:`look` reads, half a cell
    apart along ``look_rays`` rays out to ``look_radius_m``."""
    step = 0.5 * grid.resolution
    d = np.arange(1, int(np.ceil(params.look_radius_m / step)) + 1) * step
    angles = np.linspace(-np.pi, np.pi, params.look_rays, endpoint=False)
    return np.stack([np.cos(angles)[:, None] * d[None, :], np.sin(angles)[:, None] * d[None, :]])


@dataclass
class LookedAt:
    """The cells looked at from within reading range (:func:`look`) and where the latest look was taken."""

    covered: np.ndarray | None = None  # bool, the grid's shape
    at: tuple[float, float, int] | None = None  # x m, y m and the grid's version at the latest look
    rays: np.ndarray | None = None  # :func:`look_rays` for the grid, worked out once

    def update(self, grid: OccupancyGrid, robot_xy: np.ndarray, params: FrontierParams) -> np.ndarray:
        """:attr:`covered` after a look from ``robot_xy`` (m), taken only when the robot has moved
        ``look_every_m`` since the latest look or the map has grown since: a look is all round, so turning on
        the spot adds nothing. A grid of another shape starts the record afresh."""
        if self.covered is None or self.covered.shape != grid.shape:
            self.covered, self.at = np.zeros(grid.shape, dtype=bool), None
            self.rays = look_rays(grid, params)
        if self.at is not None and self.at[2] == grid.version and \
                float(np.hypot(robot_xy[0] - self.at[0], robot_xy[1] - self.at[1])) < params.look_every_m:
            return self.covered
        look(grid, self.covered, robot_xy, params, self.rays)
        self.at = (float(robot_xy[0]), float(robot_xy[1]), grid.version)
        return self.covered


def frontier_mask(grid: OccupancyGrid, robot_radius_m: float, params: FrontierParams,
                  covered: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(frontier cells, passable cells), both bool (rows, cols); ``covered``: cells looked at (see :func:`look`).

    Worked out on the known cells' bounding box with a margin (:func:`known_box`): both masks are empty
    farther out, and every step within looks no farther than the margin (the clearance is wanted only up to
    the robot's radius), so the answer is the whole grid's."""
    frontier, passable = np.zeros(grid.shape, dtype=bool), np.zeros(grid.shape, dtype=bool)
    box = known_box(grid, _margin_cells(grid, params))
    if box is None:
        return frontier, passable
    rows, cols = box
    window = _window(grid, rows.start, rows.stop, cols.start, cols.stop)
    frontier[box], passable[box] = _frontier_mask(window, robot_radius_m, params,
                                                  None if covered is None else covered[box])
    return frontier, passable


def known_box(grid: OccupancyGrid, margin_cells: int) -> tuple[slice, slice] | None:
    """(rows, cols) slices of the bounding box of the grid's known cells grown by ``margin_cells`` (cut to the
    grid), or None when no cell is known."""
    known = (grid.log_odds > grid.params.occupied_threshold) | (grid.log_odds < grid.params.free_threshold)
    rows, cols = np.flatnonzero(known.any(axis=1)), np.flatnonzero(known.any(axis=0))
    if rows.size == 0:
        return None
    n_rows, n_cols = grid.shape
    return (slice(max(0, rows[0] - margin_cells), min(n_rows, rows[-1] + margin_cells + 1)),
            slice(max(0, cols[0] - margin_cells), min(n_cols, cols[-1] + margin_cells + 1)))


def _margin_cells(grid: OccupancyGrid, params: FrontierParams) -> int:
    """Cells around the known ones that :func:`frontier_mask` must see: the closing's reach (filled space lies
    within the known cells' box) and the reach to unseen space, plus one."""
    return max(params.fill_holes_cells, _reach_cells(grid, params)) + 1


def _reach_cells(grid: OccupancyGrid, params: FrontierParams) -> int:
    """``reach_m`` in cells of ``grid`` (at least one)."""
    return max(1, int(round(params.reach_m / grid.resolution)))


def _frontier_mask(grid: OccupancyGrid, robot_radius_m: float, params: FrontierParams,
                   covered: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`frontier_mask` over every cell of ``grid``."""
    filled = filled_free(grid, params.fill_holes_cells)
    clearance = clearance_m(grid, robot_radius_m)  # all that passability asks of it
    passable = seen_passable(grid, clearance, robot_radius_m, params.fill_holes_cells, filled)
    occupied = grid.occupied_mask()
    unknown = ~(grid.free_mask() | filled) & ~occupied  # the closing fills; never erodes
    if covered is not None:
        unknown |= ~covered & ~occupied
    near_unknown = ndimage.binary_dilation(unknown, structure=_EIGHT, iterations=_reach_cells(grid, params))
    frontier = passable & near_unknown
    labels, count = ndimage.label(frontier, structure=_EIGHT)
    if count:
        sizes = np.bincount(labels.ravel())
        # A group's extent: the diagonal of its bounding box, so a thin line of cells counts by its length.
        boxes = ndimage.find_objects(labels)
        extent = np.array([0.0] + [np.hypot(b[0].stop - b[0].start, b[1].stop - b[1].start) * grid.resolution
                                   for b in boxes])
        keep = (extent >= params.min_size_m) & (sizes > 0)
        keep[0] = False
        frontier = keep[labels]
    return frontier, passable


def find_frontiers(grid: OccupancyGrid, robot_xy: np.ndarray, robot_radius_m: float,
                   params: FrontierParams, covered: np.ndarray | None = None) -> Frontiers:
    """Frontier cells and path distances from ``robot_xy`` (m) through passable seen space (searched on the
    passable cells' bounding box: paths never leave it)."""
    frontier, passable = frontier_mask(grid, robot_radius_m, params, covered)
    distance = np.full(grid.shape, np.inf)
    start = grid.world_to_cell(np.asarray(robot_xy, dtype=float))[0]
    if not grid.in_bounds(start[None])[0]:
        return Frontiers(frontier, distance)
    snap = int(np.ceil(params.snap_m / grid.resolution))
    r0, c0 = max(0, start[0] - snap), max(0, start[1] - snap)
    window = passable[r0:start[0] + snap + 1, c0:start[1] + snap + 1]
    cells = np.argwhere(window)
    if cells.size == 0:
        return Frontiers(frontier, distance)
    nearest = cells[np.argmin(np.hypot(*(cells + [r0, c0] - start).T))] + [r0, c0]
    rows, cols = np.flatnonzero(passable.any(axis=1)), np.flatnonzero(passable.any(axis=0))
    box = (slice(rows[0], rows[-1] + 1), slice(cols[0], cols[-1] + 1))
    costs = np.where(passable[box], 1.0, np.inf)
    seed = (int(nearest[0] - rows[0]), int(nearest[1] - cols[0]))
    cumulative, _ = MCP_Geometric(costs, fully_connected=True).find_costs([seed])
    offset = float(np.hypot(*(nearest - start))) * grid.resolution
    distance[box] = np.where(np.isfinite(cumulative), cumulative * grid.resolution + offset, np.inf)
    return Frontiers(frontier, distance)


def nearest_frontier(grid: OccupancyGrid, robot_xy: np.ndarray, robot_radius_m: float, params: FrontierParams,
                     visited: list[np.ndarray] | None = None, covered: np.ndarray | None = None,
                     value: np.ndarray | None = None, offset_m: float = 0.0, floor: float = 1e-6
                     ) -> np.ndarray | None:
    """The reachable frontier cell (m) nearest the robot by path, away from ``visited``; None if none is left.

    With ``value`` (the grid's shape, >= 0: what reaching each cell is worth) the cell of least
    ``(path + offset_m) / value`` instead: the most value per metre, a value below ``floor`` times the best
    counting as that (nowhere is ruled out)."""
    found = find_frontiers(grid, robot_xy, robot_radius_m, params, covered)
    candidates = found.mask & np.isfinite(found.distance_m) & (found.distance_m >= params.min_distance_m)
    cells = np.argwhere(candidates)
    if cells.size == 0:
        return None
    xy = grid.cell_to_world(cells)
    if visited:
        seen = np.asarray(visited, dtype=float)
        far = np.min(np.hypot(xy[:, None, 0] - seen[None, :, 0], xy[:, None, 1] - seen[None, :, 1]), axis=1)
        keep = far > params.visited_radius_m
        cells, xy = cells[keep], xy[keep]
        if cells.size == 0:
            return None
    cost = found.distance_m[cells[:, 0], cells[:, 1]]
    if value is not None:
        worth = value[cells[:, 0], cells[:, 1]]
        cost = (cost + offset_m) / np.maximum(worth, floor * max(float(worth.max()), 1e-300))
    return xy[int(np.argmin(cost))]


def still_frontier(grid: OccupancyGrid, target_xy: np.ndarray, robot_radius_m: float, params: FrontierParams,
                   covered: np.ndarray | None = None, margin_m: float = 2.0) -> bool:
    """Whether a frontier cell lies within ``reach_m`` plus one cell of ``target_xy`` (m).

    Judged on a window of the grid ``margin_m`` around the target (clearances and frontier groups
    farther away do not change the answer there), so it costs little on a large map.
    """
    rc = grid.world_to_cell(np.asarray(target_xy, dtype=float))[0]
    pad = int(np.ceil(margin_m / grid.resolution))
    rows, cols = grid.shape
    r0, r1 = max(0, rc[0] - pad), min(rows, rc[0] + pad + 1)
    c0, c1 = max(0, rc[1] - pad), min(cols, rc[1] + pad + 1)
    if r0 >= r1 or c0 >= c1:
        return False
    window = _window(grid, r0, r1, c0, c1)
    frontier, _ = frontier_mask(window, robot_radius_m, params, None if covered is None else covered[r0:r1, c0:c1])
    reach = int(np.ceil(params.reach_m / grid.resolution)) + 1
    local = rc - [r0, c0]
    near = frontier[max(0, local[0] - reach):local[0] + reach + 1, max(0, local[1] - reach):local[1] + reach + 1]
    return bool(near.any())


def _window(grid: OccupancyGrid, r0: int, r1: int, c0: int, c1: int) -> OccupancyGrid:
    """The cells [r0:r1, c0:c1] of ``grid`` as a grid of their own (same cells, same world positions)."""
    x0, y0 = grid.origin
    res = grid.resolution
    bounds = (x0 + c0 * res, x0 + c1 * res, y0 + (grid.shape[0] - r1) * res, y0 + (grid.shape[0] - r0) * res)
    window = OccupancyGrid.__new__(OccupancyGrid)
    window.params = replace(grid.params, bounds=bounds)
    window.log_odds = grid.log_odds[r0:r1, c0:c1]
    window.version = grid.version
    return window
