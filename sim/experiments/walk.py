"""Where a trial's walk went: far from the goal, near it but not seeing its label, or seeing the label unread.

SPL says how much longer than the oracle a walk was, not where the extra
metres went. Two moments split a walk, both judged from the world's truth (its
floor plan and the goal's labels), never from what the robot knew:

- *near*: the first time the robot stood within ``near_m`` of a pose that reads
  a goal label, by a path over the floor plan (the oracle's own distance to go);
- *seen*: the first time a goal label lay within the spotting rule
  (:class:`sim.perception.spotting.SpotParams`: 8 m, 75 degrees off its normal,
  in sight over the floor plan), seen to hang there but not yet read.

The walk before the first of the two is *far*; from there until *seen* it is
*near, unseen*; from *seen* to the end it is *seen, unread*. An oracle walk is
far but for its last ``near_m`` or so, and reads its label within a few metres
of seeing it, so metres well beyond those in the later phases are a search that
came close and turned away. Sight lines are tested on the floor plan from the
robot's centre (the spotter tests them in the scene from the camera), which is
close enough to count metres by. World frame, metres.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from sim.perception.spotting import SpotParams
from sim.world.data import World
from sim.world.oracle import OracleParams, distance_field, free_cells, pool_plan, readable_cells

PHASES = ("far", "near, unseen", "seen, unread")  # a walk's phases, in the order they come


@dataclass(frozen=True)
class WalkParams:
    """What "near" and "seen" mean."""

    near_m: float = 8.0  # m to go, by the floor plan, to a pose that reads the label: twice the reading range,
    # about the length of corridor a label's plate can be spotted along
    cell_m: float = 0.1  # m, grid of the distance to go: phases are counted in metres, and a quarter of the
    # oracle's cells costs a sixteenth of its search
    snap_m: float = 0.5  # m; a pose within the robot's radius of a wall (off the planner's free cells) takes
    # the least distance to go within this much of it


@dataclass(frozen=True)
class WalkMarks:
    """How far the robot had walked (m) when it first came near the goal's label and first saw it (None:
    never)."""

    near_at_m: float | None
    seen_at_m: float | None


def walk_marks(world: World, goal: str, trajectory: np.ndarray, distance_m: float, *,
               spot: SpotParams | None = None, params: WalkParams = WalkParams()) -> WalkMarks:
    """The moments :class:`WalkMarks` of a walk along ``trajectory`` (rows t s, x m, y m, ...: the true pose),
    as distances walked scaled so that the whole path is ``distance_m`` (the trial's own odometry); ``spot``
    is the spotting rule that says when a label is seen (None: the spotter's own)."""
    spot = spot or SpotParams()
    poses, walked = _walked(trajectory, distance_m)
    if len(poses) == 0:
        return WalkMarks(None, None)
    labels = world.label_tags(goal)
    plan = pool_plan(world.floorplan, params.cell_m)
    reading = OracleParams(cell_m=params.cell_m)
    seeing = OracleParams(cell_m=params.cell_m, read_range_m=spot.range_m, cone_half_angle_deg=spot.cone_half_angle_deg)
    free = free_cells(plan, reading.robot_radius_m)
    sources = np.zeros_like(free)
    seen = np.zeros_like(free)
    for tag in labels:
        sources |= readable_cells(plan, tag, reading) & free
        seen |= readable_cells(plan, tag, seeing)
    if sources.any():
        to_go, _ = distance_field(free, [tuple(cell) for cell in np.argwhere(sources)])
        to_go = to_go * plan.resolution
        snap = max(1, int(round(params.snap_m / plan.resolution)))
        to_go = np.where(np.isfinite(to_go), to_go, ndimage.minimum_filter(to_go, size=2 * snap + 1))
    else:
        to_go = np.full(free.shape, np.inf)
    rows, cols = free.shape
    cells = plan.world_to_pixel(poses)
    inside = (cells[:, 0] >= 0) & (cells[:, 0] < rows) & (cells[:, 1] >= 0) & (cells[:, 1] < cols)
    r, c = np.clip(cells[:, 0], 0, rows - 1), np.clip(cells[:, 1], 0, cols - 1)
    return WalkMarks(_first(walked, inside & (to_go[r, c] <= params.near_m)), _first(walked, inside & seen[r, c]))


def point_at(trajectory: np.ndarray, distance_m: float, at_m: float) -> tuple[float, float]:
    """The point (x, y m) of ``trajectory`` (rows t s, x m, y m, ...) where the robot had walked ``at_m``, the
    walk's length counted as ``distance_m`` (the trial's odometry) as :func:`walk_marks` counts it."""
    poses, walked = _walked(trajectory, distance_m)
    if walked[-1] <= 0:
        return float(poses[0, 0]), float(poses[0, 1])
    return float(np.interp(at_m, walked, poses[:, 0])), float(np.interp(at_m, walked, poses[:, 1]))


def _walked(trajectory: np.ndarray, distance_m: float) -> tuple[np.ndarray, np.ndarray]:
    """The poses (N, 2 m) of ``trajectory`` (rows t s, x m, y m, ...) and the distance walked at each (m),
    scaled so that the whole path is ``distance_m`` (all zero for a path that never moves)."""
    rows = np.asarray(trajectory, dtype=float)
    if rows.size == 0:
        return np.zeros((0, 2)), np.zeros(0)
    poses = rows.reshape(len(rows), -1)[:, 1:3]
    walked = np.r_[0.0, np.cumsum(np.hypot(*np.diff(poses, axis=0).T))]
    return poses, walked * (distance_m / walked[-1]) if walked[-1] > 0 else np.zeros_like(walked)


def _first(walked: np.ndarray, hit: np.ndarray) -> float | None:
    """The distance walked (m) at the first true entry of ``hit``, or None."""
    return float(walked[int(np.argmax(hit))]) if hit.any() else None


def phases(distance_m: float, near_at_m: float | None, seen_at_m: float | None) -> tuple[float, float, float]:
    """The walk of ``distance_m`` (m) split into :data:`PHASES` by its marks (m walked when first near and first
    seen; None: never)."""
    seen = distance_m if seen_at_m is None else min(seen_at_m, distance_m)
    close = seen if near_at_m is None else min(near_at_m, seen)
    return close, seen - close, distance_m - seen


def phase_means(records: Iterable[dict]) -> tuple[int, Sequence[float]] | None:
    """Over the records that carry marks (``near_at_m``, ``seen_at_m``) and a distance: how many, and the mean
    metres per trial of each of :data:`PHASES`; None when no record carries them."""
    split = [phases(float(r["distance_m"]), r.get("near_at_m"), r.get("seen_at_m")) for r in records
             if r.get("distance_m") is not None and "near_at_m" in r and "seen_at_m" in r]
    if not split:
        return None
    return len(split), [float(v) for v in np.mean(split, axis=0)]
