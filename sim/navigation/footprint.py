"""Whether a drive command would put the robot's body on a mapped wall: checked before the robot drives.

Pure pursuit steers at a carrot ``FollowerParams.lookahead_m`` along the path
and drives on while it turns, so it cuts the path's corners. At a 1 m door the
planned path leaves 0.12 m each side of the 0.38 m robot radius, and a robot
that comes at the door off its line and turns in on the move puts a front
corner on the jamb. Pushed there, the corner cannot turn and no wheel moves;
the stuck recovery backs the robot off 0.2 m and turns it, and the follower
drives it back onto the same jamb (traced: campus 23 "Biology Staff Room 2",
over a minute at one door). So before a command is sent, the body is swept
along the arc that command drives (``FootprintParams.horizon_m`` of it, or
``turn_rad`` of a turn on the spot) over the occupancy grid: a command that
would put more of the body on mapped wall than lies there now is
:func:`blocked`. The follower then steers at nearer carrots, which turn the
robot back onto its path first (the path keeps the robot radius from every
mapped wall), and failing those creeps straight ahead or back
(``creep_mps``): a robot in a doorway whose corners cannot turn there leaves
the doorway before it turns (traced: office 16 "Support Meeting Room 3",
where ten recoveries in a row left the robot wedged in a door it had to turn
round in).

The body is the GuiaBot's rectangle (:class:`sim.world.robot.RobotParams`),
sampled at points over its area. World frame, metres, radians
counter-clockwise from +x.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from sim.mapping.occupancy import OccupancyGrid


@dataclass(frozen=True)
class FootprintParams:
    """The body swept, and how far ahead."""

    length_m: float = 0.59  # m along the heading: the GuiaBot's footprint (sim.world.robot.RobotParams.length)
    width_m: float = 0.48  # m across the heading (RobotParams.width)
    margin_m: float = 0.05  # m added on every side: half a grid cell, as a mapped wall's face lies anywhere in its cell
    horizon_m: float = 0.3  # m along the arc swept: about a second at full speed, more than the corner of a door
    # overhangs the path when the robot turns in on the move (its front corner lies 0.38 m out)
    turn_rad: float = 0.3  # rad of a turn on the spot swept: its corners (0.38 m out) sweep 0.11 m, as a drive does
    step_m: float = 0.05  # m between the body's sample points, and between the poses swept: half a grid cell
    lookaheads_m: tuple[float, ...] = (0.4, 0.2)  # m, nearer carrots tried in turn when the follower's own command
    # is blocked: halving towards the path's nearest point, so the robot turns back onto its path before it drives
    creep_mps: float = 0.1  # m/s straight ahead, else back, when every carrot's command is blocked: a quarter of full
    # speed; a steady creep covers 0.4 m in the stuck detector's 4 s window (it asks 0.1 m), a robot rocking on the
    # spot between creeps ahead and back does not, and is still backed off

    def __post_init__(self) -> None:
        for name in ("length_m", "width_m", "horizon_m", "turn_rad", "step_m", "creep_mps"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"FootprintParams.{name} must be finite and > 0, got {value}")
        if not (math.isfinite(self.margin_m) and self.margin_m >= 0):
            raise ValueError(f"FootprintParams.margin_m must be finite and >= 0, got {self.margin_m}")
        if not all(math.isfinite(v) and v > 0 for v in self.lookaheads_m):
            raise ValueError(f"FootprintParams.lookaheads_m must all be finite and > 0, got {self.lookaheads_m}")


def body_points(params: FootprintParams) -> np.ndarray:
    """(N, 2) m: points over the body's rectangle grown by ``margin_m``, in the robot frame (x ahead, y left),
    ``step_m`` apart with its edges included."""
    half_l, half_w = params.length_m / 2 + params.margin_m, params.width_m / 2 + params.margin_m
    xs = np.linspace(-half_l, half_l, max(2, int(math.ceil(2 * half_l / params.step_m)) + 1))
    ys = np.linspace(-half_w, half_w, max(2, int(math.ceil(2 * half_w / params.step_m)) + 1))
    gx, gy = np.meshgrid(xs, ys)
    return np.column_stack([gx.ravel(), gy.ravel()])


def swept_poses(pose: tuple[float, float, float], v: float, w: float, params: FootprintParams) -> np.ndarray:
    """(K, 3): the poses (x m, y m, theta rad) the command (``v`` m/s, ``w`` rad/s) passes through from ``pose``
    (excluded): every ``step_m`` along its arc (ahead for ``v`` > 0, back for ``v`` < 0) out to ``horizon_m``, or
    for a turn on the spot (``v`` = 0) every ``step_m`` of the body's corners out to ``turn_rad``; none when the
    command is (0, 0)."""
    x, y, theta = pose
    if v == 0.0:
        if w == 0.0:
            return np.zeros((0, 3))
        corner = math.hypot(params.length_m, params.width_m) / 2 + params.margin_m
        turned = np.arange(1, int(math.ceil(params.turn_rad * corner / params.step_m)) + 1) * params.step_m / corner
        heading = theta + math.copysign(1.0, w) * turned
        return np.column_stack([np.full_like(turned, x), np.full_like(turned, y), heading])
    s = math.copysign(1.0, v) * np.arange(1, int(math.ceil(params.horizon_m / params.step_m)) + 1) * params.step_m
    curvature = w / v
    heading = theta + curvature * s
    if abs(curvature) < 1e-9:
        return np.column_stack([x + s * math.cos(theta), y + s * math.sin(theta), heading])
    return np.column_stack([x + (np.sin(heading) - math.sin(theta)) / curvature,
                            y - (np.cos(heading) - math.cos(theta)) / curvature, heading])


def wall_counts(grid: OccupancyGrid, poses: np.ndarray, body: np.ndarray) -> np.ndarray:
    """(K,): how many of the ``body`` points (robot frame) lie on mapped wall at each of ``poses`` (K, 3)."""
    poses = np.atleast_2d(poses)
    cos, sin = np.cos(poses[:, 2])[:, None], np.sin(poses[:, 2])[:, None]
    wx = poses[:, 0:1] + cos * body[None, :, 0] - sin * body[None, :, 1]
    wy = poses[:, 1:2] + sin * body[None, :, 0] + cos * body[None, :, 1]
    on_wall = grid.occupied_cells(grid.world_to_cell(np.column_stack([wx.ravel(), wy.ravel()])))
    return on_wall.reshape(len(poses), -1).sum(axis=1)


def clear_of_walls(grid: OccupancyGrid, pose: tuple[float, float, float], params: FootprintParams = FootprintParams(),
                   body: np.ndarray | None = None) -> Callable[[float, float], bool]:
    """The question ``clear(v, w)`` for commands from ``pose``: whether the command (``v`` m/s, ``w`` rad/s) puts no
    more of the body on mapped wall than lies there now, anywhere it sweeps (:func:`swept_poses`). A body already
    touching a wall may still move off or along it; standing still is always clear. The body's count at ``pose``
    is worked out once, however many commands are asked about. ``body``: :func:`body_points`, when at hand."""
    body = body_points(params) if body is None else body
    now = wall_counts(grid, np.asarray(pose, dtype=float), body)[0]

    def clear(v: float, w: float) -> bool:
        ahead = swept_poses(pose, v, w, params)
        return len(ahead) == 0 or not bool(np.any(wall_counts(grid, ahead, body) > now))

    return clear


def blocked(grid: OccupancyGrid, pose: tuple[float, float, float], v: float, w: float,
            params: FootprintParams = FootprintParams(), body: np.ndarray | None = None) -> bool:
    """Whether the command (``v`` m/s, ``w`` rad/s) from ``pose`` is not :func:`clear_of_walls`."""
    return not clear_of_walls(grid, pose, params, body)(v, w)
