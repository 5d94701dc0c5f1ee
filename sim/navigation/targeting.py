"""Where to drive for an imagined goal: the goal itself, or the nearest seen point to it.

Planning treats unseen space as free, so an imagined goal that lies behind a
wall (the abstract map knows nothing of walls) can produce a plan that tours
the outside of the building. When the plan to the goal is a long detour
compared with the straight line, the target becomes the reachable cell of
already-seen free space nearest the goal: the robot looks there, and if the
goal's label is not in sight the navigator grows the model as usual.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from sim.mapping.occupancy import OccupancyGrid
from sim.navigation.planner import PlannerParams, plan


@dataclass(frozen=True)
class TargetParams:
    """When a plan counts as a detour, and how seen space is judged."""

    detour_ratio: float = 2.5  # plan length / straight-line distance beyond which the goal is "behind walls"
    detour_slack_m: float = 12.0  # ... and the plan must also be at least this much longer than the line (m)
    fill_holes_cells: int = 2  # closing iterations that fill unseen specks between laser beams
    view_clearance_m: float = 1.2  # m from walls wanted at a stand-in target, so labels on them are legible
    view_slack_m: float = 2.0  # m farther from the goal than the nearest seen cell a roomier cell may be
    local_bumps: int = 4  # after this many exploration bumps in a row, long detours are allowed again


@dataclass(frozen=True)
class Target:
    xy: np.ndarray  # m, world frame
    local: bool  # True when it stands in for a goal behind walls


def clearance_m(grid: OccupancyGrid) -> np.ndarray:
    """Distance (m) from each cell to the nearest seen obstacle."""
    return ndimage.distance_transform_edt(~grid.occupied_mask()) * grid.resolution


def filled_free(grid: OccupancyGrid, fill_holes_cells: int) -> np.ndarray:
    """Cells seen free with unseen specks between beams filled (``fill_holes_cells`` closing iterations; none: the
    free cells). Near the grid's edge the closing may also drop a free cell."""
    free = grid.free_mask()
    return ndimage.binary_closing(free, iterations=fill_holes_cells) if fill_holes_cells > 0 else free


def seen_passable(grid: OccupancyGrid, clearance: np.ndarray, robot_radius_m: float,
                  fill_holes_cells: int, filled: np.ndarray | None = None) -> np.ndarray:
    """Cells seen free (small unseen specks filled), more than the robot's radius (m) from any seen obstacle;
    ``filled``: :func:`filled_free` of the grid when already at hand."""
    if filled is None:
        filled = filled_free(grid, fill_holes_cells)
    return filled & (clearance > 0) & (clearance > robot_radius_m)


def nearest_seen_point(grid: OccupancyGrid, robot_xy: np.ndarray, goal_xy: np.ndarray, *,
                       robot_radius_m: float, fill_holes_cells: int = 2, view_clearance_m: float = 0.0,
                       view_slack_m: float = 0.0) -> np.ndarray | None:
    """A cell near ``goal_xy`` that the robot can reach through seen free space, or None.

    Of the reachable cells at most ``view_slack_m`` farther from the goal than the
    nearest one, the one with the most room (clearance from seen obstacles, counted
    up to ``view_clearance_m``) is chosen; ties go to the nearer.
    """
    clearance = clearance_m(grid)
    passable = seen_passable(grid, clearance, robot_radius_m, fill_holes_cells)
    components, _ = ndimage.label(passable, structure=np.ones((3, 3), dtype=bool))
    rc = grid.world_to_cell(np.asarray(robot_xy, dtype=float))[0]
    if not grid.in_bounds(rc[None])[0]:
        return None
    # The robot's own cell may sit in the clearance band: take the component of the nearest passable cell.
    window = components[max(0, rc[0] - 5):rc[0] + 6, max(0, rc[1] - 5):rc[1] + 6]
    labels = window[window > 0]
    if labels.size == 0:
        return None
    cells = np.argwhere(components == np.bincount(labels).argmax())
    xy = grid.cell_to_world(cells)
    distance = np.hypot(*(xy - np.asarray(goal_xy)).T)
    near = distance <= distance.min() + view_slack_m
    room = np.minimum(clearance[cells[near, 0], cells[near, 1]], view_clearance_m)
    order = np.lexsort((distance[near], -np.round(room, 2)))
    return xy[near][order[0]]


def choose_target(grid: OccupancyGrid, robot_xy: np.ndarray, goal_xy: np.ndarray, planner: PlannerParams,
                  params: TargetParams, *, allow_detours: bool) -> Target:
    """The imagined goal, unless reaching it means a long detour through unseen space."""
    goal = np.asarray(goal_xy, dtype=float)
    if allow_detours:
        return Target(goal, False)
    route = plan(grid, robot_xy, goal, planner)
    straight = math.hypot(*(goal - np.asarray(robot_xy, dtype=float)))
    if route is not None and route.length_m <= max(params.detour_ratio * straight, straight + params.detour_slack_m):
        return Target(goal, False)
    local = nearest_seen_point(grid, np.asarray(robot_xy, dtype=float), goal, robot_radius_m=planner.robot_radius_m,
                               fill_holes_cells=params.fill_holes_cells, view_clearance_m=params.view_clearance_m,
                               view_slack_m=params.view_slack_m)
    return Target(goal, False) if local is None else Target(local, True)
