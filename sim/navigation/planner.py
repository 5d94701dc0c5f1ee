"""Shortest paths over an occupancy grid that treat unseen space as traversable.

Frames: world frame, metres. Occupied cells grown by the robot radius are
impassable; a soft band beyond that costs extra so paths keep clearance;
unknown cells cost ``unknown_cost`` (1.0: as cheap as free, so the robot
plans straight lines through space it has not seen). Clearance is measured
from a cell centre to the nearest face of an occupied cell.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from skimage.graph import MCP_Geometric

from sim.mapping.occupancy import OccupancyGrid

_EIGHT_CONNECTED = np.ones((3, 3), dtype=bool)
_MAX_REPAIRS = 8  # coarse blocks closed before giving up on the coarse-to-fine search


@dataclass(frozen=True)
class PlannerParams:
    """Cost model and search settings of :func:`plan`."""

    robot_radius_m: float = 0.38  # m; cells closer than this to an obstacle face are impassable
    inflation_margin_m: float = 0.3  # m beyond the radius where the soft extra cost decays to 0
    inflation_cost: float = 4.0  # extra cost per cell at the radius, falling linearly to 0 at the margin
    unknown_cost: float = 1.0  # cost per cell of unknown space (free cells cost 1.0)
    escape_cost: float = 20.0  # cost per cell of impassable-but-not-occupied cells near the start
    goal_snap_radius_m: float = 1.5  # m; how far from an unreachable goal a substitute cell may lie
    coarse_factor: int = 4  # cells per side of a coarse block for the first search; 1 = single fine search
    corridor_m: float = 0.8  # m each side of the coarse path the fine search may use

    def __post_init__(self) -> None:
        for name in ("robot_radius_m", "inflation_margin_m", "inflation_cost", "goal_snap_radius_m", "corridor_m"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"PlannerParams.{name} must be finite and >= 0, got {value}")
        for name in ("unknown_cost", "escape_cost"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"PlannerParams.{name} must be finite and > 0, got {value}")
        if self.coarse_factor < 1:
            raise ValueError(f"PlannerParams.coarse_factor must be >= 1, got {self.coarse_factor}")


@dataclass(frozen=True)
class Plan:
    """A path from the start to the goal (or to the reachable cell nearest it)."""

    waypoints: np.ndarray  # (N, 2) m, world frame; first = start, last = goal_xy; N >= 2
    length_m: float  # m, along the waypoints
    goal_reached_exactly: bool  # False when the goal was blocked, off the grid or cut off: a nearby cell is used
    goal_xy: tuple[float, float]  # m, where the path actually ends


@dataclass(frozen=True)
class CostMap:
    """Per-cell costs for planning; ``costs`` is inf where impassable."""

    costs: np.ndarray  # (rows, cols) float
    lethal: np.ndarray  # (rows, cols) bool: occupied or within robot_radius_m of an occupied face
    occupied: np.ndarray  # (rows, cols) bool


def distance_to_occupied(occupied: np.ndarray, cap_cells: int) -> np.ndarray:
    """Euclidean distance (cells, centre to centre) from each cell to the nearest True cell.

    Exact up to ``cap_cells`` and inf beyond it. Separable and capped (small
    integer arithmetic), so several times cheaper than a full EDT.
    """
    occ = np.asarray(occupied, dtype=bool)
    rows, cols = occ.shape
    cap = max(0, int(cap_cells))
    if cap > 180:
        raise ValueError(f"distance_to_occupied: cap_cells must be <= 180, got {cap_cells}")
    # Distance along the row to the nearest True cell, cap + 1 if none within cap.
    along_row = np.full(occ.shape, cap + 1, dtype=np.uint16)
    for dc in range(cap, 0, -1):
        near = np.zeros(occ.shape, dtype=bool)
        near[:, :cols - dc] |= occ[:, dc:]
        near[:, dc:] |= occ[:, :cols - dc]
        along_row[near] = dc
    along_row[occ] = 0
    squared = along_row * along_row
    best = squared.copy()
    for dr in range(1, cap + 1):
        lift = np.uint16(dr * dr)
        np.minimum(best[:rows - dr], squared[dr:] + lift, out=best[:rows - dr])
        np.minimum(best[dr:], squared[:rows - dr] + lift, out=best[dr:])
    distance = np.sqrt(best.astype(np.float32))
    distance[best > cap * cap] = np.inf
    return distance


def clearance_m(grid: OccupancyGrid, up_to_m: float) -> np.ndarray:
    """Per cell of ``grid``, the distance (m, centre to centre) to the nearest mapped wall: exact up to just past
    ``up_to_m`` (all a caller asks of it), inf beyond (:func:`distance_to_occupied`)."""
    cap = int(math.ceil(up_to_m / grid.resolution)) + 1
    return distance_to_occupied(grid.occupied_mask(), cap).astype(float) * grid.resolution


def cost_map(grid: OccupancyGrid, params: PlannerParams = PlannerParams()) -> CostMap:
    """Costs of every cell of ``grid`` under ``params`` (no start-escape zone)."""
    occupied = grid.occupied_mask()
    res = grid.resolution
    reach_m = params.robot_radius_m + params.inflation_margin_m + 0.5 * res
    clearance = distance_to_occupied(occupied, int(math.ceil(reach_m / res)) + 1) * res - 0.5 * res
    lethal = clearance < params.robot_radius_m  # occupied cells have clearance -res/2
    costs = np.where(grid.unknown_mask(), params.unknown_cost, 1.0)
    if params.inflation_margin_m > 0 and params.inflation_cost > 0:
        band = np.isfinite(clearance) & ~lethal
        depth = (params.robot_radius_m + params.inflation_margin_m - clearance[band]) / params.inflation_margin_m
        costs[band] += params.inflation_cost * np.clip(depth, 0.0, 1.0)
    costs[lethal] = np.inf
    return CostMap(costs=costs, lethal=lethal, occupied=occupied)


def plan(
    grid: OccupancyGrid,
    start_xy: tuple[float, float] | np.ndarray,
    goal_xy: tuple[float, float] | np.ndarray,
    params: PlannerParams = PlannerParams(),
) -> Plan | None:
    """Cheapest path from ``start_xy`` to ``goal_xy`` (m, world frame), or None if none exists.

    If the start is in the impassable band (the robot brushing a wall), the
    non-occupied cells around it become passable at ``escape_cost``. If the
    goal is impassable, off the grid, or cut off from the start, the path ends
    at the reachable cell nearest the goal within ``goal_snap_radius_m`` of
    it (of its nearest grid cell when off the grid) and ``goal_reached_exactly``
    is False; with no such cell the result is None. The start must lie on the grid.

    Search: a straight line when it only crosses cells of the lowest cost;
    otherwise a search over ``coarse_factor``-sized blocks (each as cheap as
    its cheapest cell) then a fine search in a corridor around that route
    (see :func:`_search`), then line-of-sight shortcuts that never raise the
    path's cost.
    """
    start = as_point(start_xy, "start_xy")
    goal = as_point(goal_xy, "goal_xy")
    start_rc = grid.world_to_cell(start)[0]
    if not grid.in_bounds(start_rc)[0]:
        raise ValueError(f"plan: start_xy {tuple(start)} lies outside the grid extent {grid.extent}")
    cmap = cost_map(grid, params)
    costs = _with_escape_zone(grid, cmap, start, start_rc, params)

    labels, _ = ndimage.label(np.isfinite(costs), structure=_EIGHT_CONNECTED)
    component = labels == labels[start_rc[0], start_rc[1]]
    target_rc, exact = _target_cell(grid, component, goal, params)
    if target_rc is None:
        return None
    end_xy = goal if exact else grid.cell_to_world(target_rc[None, :])[0]

    cheapest = min(1.0, params.unknown_cost, params.escape_cost)
    line = segment_cells(grid, start, end_xy)
    if np.all(costs[line[:, 0], line[:, 1]] <= cheapest + 1e-9):
        waypoints = np.stack([start, end_xy])
    else:
        reachable = np.where(component, costs, np.inf)  # no detours via pockets cut off from the start
        found = _search(reachable, start_rc, target_rc, params, grid.resolution)
        if found is None:
            return None
        waypoints = _simplify(grid, costs, found[0], found[1], start, end_xy)
    length = float(np.sum(np.hypot(*np.diff(waypoints, axis=0).T)))
    return Plan(waypoints=waypoints, length_m=length, goal_reached_exactly=exact,
                goal_xy=(float(end_xy[0]), float(end_xy[1])))


def _mcp_path(costs: np.ndarray, start_rc: np.ndarray,
              target_rc: np.ndarray) -> tuple[np.ndarray | None, np.ndarray, np.ndarray]:
    """Cheapest 8-connected path over ``costs``: (cells (M, 2) or None, cost-to-come of each, cumulative map).

    Costs are in cell-edge lengths times cell cost (MCP_Geometric's units).
    The cumulative map is finite where the search reached (everywhere
    reachable when the target is not).
    """
    mcp = MCP_Geometric(costs, fully_connected=True)
    cumulative, _ = mcp.find_costs([tuple(start_rc)], [tuple(target_rc)], find_all_ends=True)
    if not math.isfinite(float(cumulative[target_rc[0], target_rc[1]])):
        return None, np.empty(0), cumulative
    cells = np.asarray(mcp.traceback(tuple(target_rc)), dtype=int)
    return cells, cumulative[cells[:, 0], cells[:, 1]], cumulative


def _search(costs: np.ndarray, start_rc: np.ndarray, target_rc: np.ndarray, params: PlannerParams,
            resolution: float) -> tuple[np.ndarray, np.ndarray] | None:
    """Fine cells (M, 2) from start to target and their costs-to-come.

    A block is as cheap as its cheapest cell, so the coarse route is
    optimistic: it may slip through a crack between inflated walls whose
    passable cells do not connect. The fine search runs in a corridor around
    the route; when it cannot get through, the first route block it could
    not reach is closed and the coarse route recomputed (up to
    ``_MAX_REPAIRS`` times), and a search over the whole grid is the last resort.
    """
    f = params.coarse_factor
    if f > 1:
        rows, cols = costs.shape
        coarse_rows, coarse_cols = -(-rows // f), -(-cols // f)
        padded = np.full((coarse_rows * f, coarse_cols * f), np.inf)
        padded[:rows, :cols] = costs
        coarse = np.minimum.reduce([padded[:, k::f] for k in range(f)])
        coarse = np.minimum.reduce([coarse[k::f] for k in range(f)])
        blocks = max(1, int(math.ceil(params.corridor_m / (f * resolution))))
        for _ in range(_MAX_REPAIRS + 1):
            route = _mcp_path(coarse, start_rc // f, target_rc // f)[0]
            if route is None:
                break
            corridor = np.zeros(coarse.shape, dtype=bool)
            corridor[route[:, 0], route[:, 1]] = True
            corridor = ndimage.binary_dilation(corridor, structure=_EIGHT_CONNECTED, iterations=blocks)
            rr, cc = np.nonzero(corridor)
            r0, r1 = rr.min() * f, min(rows, (rr.max() + 1) * f)
            c0, c1 = cc.min() * f, min(cols, (cc.max() + 1) * f)
            inside = np.repeat(np.repeat(corridor, f, axis=0), f, axis=1)[r0:r1, c0:c1]
            window = np.where(inside, costs[r0:r1, c0:c1], np.inf)
            offset = np.array([r0, c0])
            cells, cost_to_come, cumulative = _mcp_path(window, start_rc - offset, target_rc - offset)
            if cells is not None:
                return cells + offset, cost_to_come
            reached = np.full(padded.shape, False)
            reached[r0:r1, c0:c1] = np.isfinite(cumulative)
            reached_blocks = reached.reshape(coarse_rows, f, coarse_cols, f).any(axis=(1, 3))
            missed = ~reached_blocks[route[:, 0], route[:, 1]]
            if not missed.any():
                break
            coarse[tuple(route[int(np.argmax(missed))])] = np.inf
    cells, cost_to_come, _ = _mcp_path(costs, start_rc, target_rc)
    return None if cells is None else (cells, cost_to_come)


def as_point(xy: tuple[float, float] | np.ndarray, name: str) -> np.ndarray:
    p = np.asarray(xy, dtype=float).ravel()
    if p.shape != (2,) or not np.all(np.isfinite(p)):
        raise ValueError(f"{name} must be two finite numbers (x m, y m), got {xy!r}")
    return p


def escape_radius(grid: OccupancyGrid, params: PlannerParams) -> float:
    return params.robot_radius_m + 2.0 * grid.resolution


def _with_escape_zone(grid: OccupancyGrid, cmap: CostMap, start: np.ndarray, start_rc: np.ndarray,
                      params: PlannerParams) -> np.ndarray:
    """Costs with the lethal, non-occupied cells near the start made passable at escape_cost."""
    costs = cmap.costs
    if not cmap.lethal[start_rc[0], start_rc[1]]:
        return costs
    costs = costs.copy()
    reach = int(math.ceil(escape_radius(grid, params) / grid.resolution))
    rows, cols = grid.shape
    r0, r1 = max(0, start_rc[0] - reach), min(rows, start_rc[0] + reach + 1)
    c0, c1 = max(0, start_rc[1] - reach), min(cols, start_rc[1] + reach + 1)
    rr, cc = np.mgrid[r0:r1, c0:c1]
    centres = grid.cell_to_world(np.stack([rr.ravel(), cc.ravel()], axis=1))
    near = (np.hypot(*(centres - start).T) <= escape_radius(grid, params)).reshape(rr.shape)
    window_lethal = cmap.lethal[r0:r1, c0:c1] & ~cmap.occupied[r0:r1, c0:c1]
    escape = near & window_lethal
    costs[r0:r1, c0:c1][escape] = params.escape_cost
    costs[start_rc[0], start_rc[1]] = params.escape_cost
    return costs


def _target_cell(grid: OccupancyGrid, component: np.ndarray, goal: np.ndarray,
                 params: PlannerParams) -> tuple[np.ndarray | None, bool]:
    """The cell to plan to and whether it holds the goal itself."""
    goal_rc = grid.world_to_cell(goal)[0]
    if grid.in_bounds(goal_rc)[0] and component[goal_rc[0], goal_rc[1]]:
        return goal_rc, True
    rows, cols = grid.shape
    anchor_rc = np.array([np.clip(goal_rc[0], 0, rows - 1), np.clip(goal_rc[1], 0, cols - 1)])
    anchor = goal if grid.in_bounds(goal_rc)[0] else grid.cell_to_world(anchor_rc[None, :])[0]
    reach = int(math.ceil(params.goal_snap_radius_m / grid.resolution)) + 1
    r0, r1 = max(0, anchor_rc[0] - reach), min(rows, anchor_rc[0] + reach + 1)
    c0, c1 = max(0, anchor_rc[1] - reach), min(cols, anchor_rc[1] + reach + 1)
    rr, cc = np.nonzero(component[r0:r1, c0:c1])
    if rr.size == 0:
        return None, False
    candidates = np.stack([rr + r0, cc + c0], axis=1)
    distance = np.hypot(*(grid.cell_to_world(candidates) - anchor).T)
    best = int(np.argmin(distance))
    if distance[best] > params.goal_snap_radius_m:
        return None, False
    return candidates[best], False


def sample_step(grid: OccupancyGrid) -> float:
    """Spacing (m) of the samples that check a segment against the cost map."""
    return 0.25 * grid.resolution


def segment_cells(grid: OccupancyGrid, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(row, col) cells (M, 2) under the segment a -> b (m), sampled every quarter cell, ends included."""
    n = max(1, int(math.ceil(float(np.hypot(*(b - a))) / sample_step(grid))))
    s = np.linspace(0.0, 1.0, n + 1)[:, None]
    return grid.world_to_cell(a[None, :] + s * (b - a)[None, :])


def _simplify(grid: OccupancyGrid, costs: np.ndarray, cells: np.ndarray, cost_to_come: np.ndarray,
              start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """A sparse polyline along the cell path: greedy straight shortcuts.

    A shortcut from vertex i to j is taken when every cell under it is
    passable and it costs no more than the path from i to j (the cost of a
    straight segment is its length in cells times the mean cost of the cells
    sampled along it), so shortcuts never trade clearance or known space for
    length beyond what the cost model allows.
    """
    points = grid.cell_to_world(cells)
    points[0], points[-1] = start, end
    rows, cols = grid.shape
    x0, y0 = grid.origin
    # Continuous cell coordinates: col = floor(u), row = rows - 1 - floor(v).
    u = (points[:, 0] - x0) / grid.resolution
    v = (points[:, 1] - y0) / grid.resolution
    step_cells = sample_step(grid) / grid.resolution

    def visible(i: int, j: int) -> bool:
        n = max(1, int(math.ceil(math.hypot(u[j] - u[i], v[j] - v[i]) / step_cells)))
        s = np.linspace(0.0, 1.0, n + 1)
        col = np.floor(u[i] + s * (u[j] - u[i])).astype(np.intp)
        row = rows - 1 - np.floor(v[i] + s * (v[j] - v[i])).astype(np.intp)
        if col.min() < 0 or col.max() >= cols or row.min() < 0 or row.max() >= rows:
            return False
        along = costs[row, col]
        if not np.all(np.isfinite(along)):
            return False
        length = math.hypot(u[j] - u[i], v[j] - v[i])
        return bool(length * along.mean() <= (cost_to_come[j] - cost_to_come[i]) * (1 + 1e-6) + 1e-9)

    last = len(points) - 1
    keep = [0]
    i = 0
    while i < last:
        # Gallop to bracket the furthest visible vertex, then bisect (lo visible, hi not).
        lo, hi, reach = i + 1, last + 1, 2
        while lo < last:
            probe = min(last, i + reach)
            if not visible(i, probe):
                hi = probe
                break
            lo, reach = probe, 2 * reach
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if visible(i, mid):
                lo = mid
            else:
                hi = mid
        keep.append(lo)
        i = lo
    return points[keep]
