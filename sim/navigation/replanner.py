"""When to plan again: a path the robot follows, checked against the growing map.

:func:`path_blocked` asks whether newly seen obstacles now lie on a path;
:class:`Replanner` keeps the current :class:`~sim.navigation.planner.Plan` and
plans again when the goal moves, the path is blocked, the robot strays, or a
period passes. Positions in metres, world frame; times in seconds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim.mapping.occupancy import OccupancyGrid
from sim.navigation.planner import Plan, PlannerParams, as_point, escape_radius, plan, sample_step

DEFAULT_PLANNER = PlannerParams()


def path_blocked(
    grid: OccupancyGrid,
    waypoints: np.ndarray,
    params: PlannerParams = DEFAULT_PLANNER,
    robot_xy: tuple[float, float] | np.ndarray | None = None,
) -> bool:
    """Whether the polyline ``waypoints`` (N, 2, m) now passes within robot_radius_m of an occupied cell.

    With ``robot_xy``, only the part of the path ahead of the robot's nearest
    point on it is checked, skipping the escape zone around the robot.
    """
    pts = np.atleast_2d(np.asarray(waypoints, dtype=float))
    if pts.shape[0] < 1 or pts.shape[1] != 2 or not np.all(np.isfinite(pts)):
        raise ValueError(f"path_blocked: waypoints must be finite (N, 2), got shape {pts.shape}")
    samples = _densify(pts, sample_step(grid))
    if robot_xy is not None:
        robot = as_point(robot_xy, "robot_xy")
        dist = np.hypot(*(samples - robot).T)
        samples = samples[int(np.argmin(dist)):]
        samples = samples[np.hypot(*(samples - robot).T) > escape_radius(grid, params)]
    if samples.size == 0:
        return False
    reach_m = params.robot_radius_m + 0.5 * grid.resolution
    reach = int(math.ceil(reach_m / grid.resolution))
    dr, dc = np.mgrid[-reach:reach + 1, -reach:reach + 1]
    disk = np.hypot(dr, dc) * grid.resolution < reach_m
    cols = grid.shape[1]
    rc = grid.world_to_cell(samples)
    rc = rc[grid.in_bounds(rc)]
    centres = np.unique(rc[:, 0] * cols + rc[:, 1])
    probe_r = centres[:, None] // cols + dr[disk][None, :]
    probe_c = centres[:, None] % cols + dc[disk][None, :]
    return bool(grid.occupied_cells(np.column_stack([probe_r.ravel(), probe_c.ravel()])).any())


def _densify(points: np.ndarray, step: float) -> np.ndarray:
    """Points every ``step`` m along a polyline, vertices included, in order."""
    if len(points) == 1:
        return points.copy()
    segments = np.diff(points, axis=0)
    counts = np.maximum(1, np.ceil(np.hypot(*segments.T) / step).astype(int))
    owner = np.repeat(np.arange(len(segments)), counts)
    index = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    fraction = index / counts[owner]
    return np.concatenate([points[:-1][owner] + fraction[:, None] * segments[owner], points[-1:]])


@dataclass(frozen=True)
class ReplanParams:
    """When :class:`Replanner` plans again."""

    goal_moved_m: float = 1.0  # m the goal may drift before re-planning
    period_s: float = 5.0  # s between routine re-plans (the map keeps growing)
    min_interval_s: float = 0.5  # s; no re-plan sooner than this after the last one, unless forced
    off_path_m: float = 1.0  # m the robot may stray from its path before re-planning
    check_blocked: bool = True  # re-plan when newly seen obstacles block the path ahead


class Replanner:
    """Keeps a current plan and decides when to plan again.

    Triggers: no plan yet, a :meth:`request`, the goal moved more than
    ``goal_moved_m``, the path ahead is blocked, the robot strayed
    ``off_path_m`` from it, or ``period_s`` passed. Times are in seconds.
    """

    def __init__(self, params: ReplanParams = ReplanParams(),
                 planner_params: PlannerParams = DEFAULT_PLANNER) -> None:
        self.params = params
        self.planner_params = planner_params
        self.plan: Plan | None = None
        self.last_reason: str | None = None
        self._planned_at: float | None = None
        self._planned_goal: np.ndarray | None = None
        self._forced = False
        self._clear_at: int | None = None  # the map version at which the current plan was last found clear

    def request(self) -> None:
        """Re-plan at the next :meth:`update` (e.g. after a recovery manoeuvre)."""
        self._forced = True

    def reason(self, t: float, grid: OccupancyGrid, robot_xy: tuple[float, float] | np.ndarray,
               goal_xy: tuple[float, float] | np.ndarray) -> str | None:
        """Why a re-plan is due at time ``t`` (s), or None."""
        robot = as_point(robot_xy, "robot_xy")
        goal = as_point(goal_xy, "goal_xy")
        if self._forced:
            return "requested"
        if self._planned_at is None or self._planned_goal is None:
            return "no plan yet"
        if t - self._planned_at < self.params.min_interval_s:
            return None
        if float(np.hypot(*(goal - self._planned_goal))) > self.params.goal_moved_m:
            return "goal moved"
        if self.plan is None:
            return "previous attempt failed" if t - self._planned_at >= self.params.period_s else None
        # The part of the path ahead only shrinks as the robot follows it, so a path found clear is checked
        # again only once the map (OccupancyGrid.version) or the plan changed.
        if self.params.check_blocked and self._clear_at != grid.version:
            if path_blocked(grid, self.plan.waypoints, self.planner_params, robot):
                return "path blocked"
            self._clear_at = grid.version
        if _distance_to_polyline(robot, self.plan.waypoints) > self.params.off_path_m:
            return "off path"
        if t - self._planned_at >= self.params.period_s:
            return "periodic"
        return None

    def update(self, t: float, grid: OccupancyGrid, robot_xy: tuple[float, float] | np.ndarray,
               goal_xy: tuple[float, float] | np.ndarray) -> Plan | None:
        """The current plan, re-planned first if :meth:`reason` says so."""
        why = self.reason(t, grid, robot_xy, goal_xy)
        if why is not None:
            self.last_reason = why
            self.plan = plan(grid, robot_xy, goal_xy, self.planner_params)
            self._planned_at = t
            self._planned_goal = as_point(goal_xy, "goal_xy")
            self._forced = False
            self._clear_at = None
        return self.plan


def _distance_to_polyline(p: np.ndarray, points: np.ndarray) -> float:
    """Shortest distance (m) from point p to the polyline ``points`` (N, 2)."""
    if len(points) == 1:
        return float(np.hypot(*(p - points[0])))
    a, b = points[:-1], points[1:]
    ab = b - a
    denom = np.maximum(np.sum(ab * ab, axis=1), 1e-12)
    s = np.clip(np.sum((p - a) * ab, axis=1) / denom, 0.0, 1.0)
    closest = a + s[:, None] * ab
    return float(np.min(np.hypot(*(closest - p).T)))
