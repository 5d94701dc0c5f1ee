"""The body swept along a drive command over the occupancy grid, and the follower that will not drive into a jamb."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sim.mapping.occupancy import OccupancyGrid, OccupancyParams
from sim.navigation.follower import FollowerParams, PathFollower
from sim.navigation.footprint import FootprintParams, blocked, body_points, clear_of_walls, swept_poses, wall_counts
from sim.world.robot import RobotParams

DT = 0.1  # s, the trials' control tick


def grid_with_wall(door_half_m: float | None = 0.5) -> OccupancyGrid:
    """A mapped wall along x in [0, 0.2] m, with a doorway |y| < ``door_half_m`` (none when None)."""
    grid = OccupancyGrid(OccupancyParams(bounds=(-3.0, 3.0, -3.0, 3.0)))
    xs, ys = grid.cell_axes()
    x, y = np.meshgrid(xs, ys)
    wall = (x >= 0.0) & (x <= 0.2)
    if door_half_m is not None:
        wall &= np.abs(y) >= door_half_m
    grid.log_odds[wall] = grid.params.clamp[1]
    return grid


def test_the_body_is_the_robots_footprint_grown_by_the_margin() -> None:
    robot, params = RobotParams(), FootprintParams()
    assert (params.length_m, params.width_m) == (robot.length, robot.width)
    pts = body_points(params)
    assert pts[:, 0].min() == pytest.approx(-(robot.length / 2 + params.margin_m))
    assert pts[:, 0].max() == pytest.approx(robot.length / 2 + params.margin_m)
    assert pts[:, 1].max() == pytest.approx(robot.width / 2 + params.margin_m)
    assert np.max(np.diff(np.unique(pts[:, 0]))) <= params.step_m + 1e-9


def test_the_poses_swept_follow_the_commanded_motion() -> None:
    params = FootprintParams()
    straight = swept_poses((1.0, 2.0, math.pi / 2), 0.4, 0.0, params)
    assert len(straight) == 6
    np.testing.assert_allclose(straight[-1], [1.0, 2.3, math.pi / 2], atol=1e-9)
    back = swept_poses((1.0, 2.0, math.pi / 2), -0.1, 0.0, params)
    np.testing.assert_allclose(back[-1], [1.0, 1.7, math.pi / 2], atol=1e-9)
    turning = swept_poses((0.0, 0.0, 0.0), 0.2, 0.4, params)  # radius v / w = 0.5 m about (0, 0.5)
    np.testing.assert_allclose(np.hypot(turning[:, 0], turning[:, 1] - 0.5), 0.5, atol=1e-9)
    np.testing.assert_allclose(turning[:, 2], 2.0 * np.arange(1, 7) * 0.05, atol=1e-9)
    on_the_spot = swept_poses((1.0, 2.0, 0.5), 0.0, -0.4, params)
    np.testing.assert_allclose(on_the_spot[:, :2], [[1.0, 2.0]] * len(on_the_spot))
    assert on_the_spot[-1, 2] == pytest.approx(0.5 - params.turn_rad, abs=0.13)  # clockwise, a corner step a pose
    assert np.all(np.diff(on_the_spot[:, 2]) < 0)
    assert len(swept_poses((1.0, 2.0, 0.5), 0.0, 0.0, params)) == 0


def test_driving_at_a_wall_is_blocked_and_along_or_away_from_it_is_not() -> None:
    grid, params = grid_with_wall(door_half_m=None), FootprintParams()
    facing = (0.75, 0.0, math.pi)  # front face 0.46 m from the wall's face at 0.2 m: 0.3 m on, it is on the wall
    assert blocked(grid, facing, 0.4, 0.0, params)
    assert not blocked(grid, facing, -0.2, 0.0, params)  # backing off from it is not
    assert not blocked(grid, facing, 0.0, 0.4, params)  # nor is turning in place, clear of it
    assert not blocked(grid, facing, 0.0, 0.0, params)
    assert not blocked(grid, (0.75, 0.0, math.pi / 2), 0.4, 0.0, params)  # along the wall, clear of it
    touching = (0.5, 0.0, math.pi)  # the grown body already on the wall
    assert wall_counts(grid, np.array(touching), body_points(params))[0] > 0
    assert blocked(grid, touching, 0.4, 0.0, params)  # pushing on: more of it on the wall
    assert not blocked(grid, (0.5, 0.0, 0.0), 0.4, 0.0, params)  # the same spot, driving away
    assert blocked(grid, (0.5, 0.0, 0.0), -0.1, 0.0, params)  # backing into it


def test_a_turn_whose_corners_would_sweep_a_jamb_is_blocked() -> None:
    grid, params = grid_with_wall(door_half_m=0.5), FootprintParams()
    in_the_door = (0.1, -0.17, 0.0)  # facing through the doorway, 0.17 m off its middle
    assert not blocked(grid, in_the_door, 0.1, 0.0, params)  # it may go on through
    assert blocked(grid, in_the_door, 0.0, 0.4, params)
    assert blocked(grid, in_the_door, 0.0, -0.4, params)
    assert not blocked(grid, (1.5, 0.0, 0.0), 0.0, 0.4, params)  # in the open


def test_a_bad_footprint_is_refused() -> None:
    with pytest.raises(ValueError, match="FootprintParams.width_m"):
        FootprintParams(width_m=0.0)
    with pytest.raises(ValueError, match="lookaheads_m"):
        FootprintParams(lookaheads_m=(0.4, -0.2))


def drive_through(grid: OccupancyGrid, start: tuple[float, float, float], path: list[tuple[float, float]],
                  check: bool, steps: int = 400) -> tuple[bool, int, list[tuple[float, float, float]]]:
    """Unicycle steps of the follower along ``path``; a step that would put the bare body on the wall is not taken
    (a body pushed on a jamb stays). (arrived, steps refused, poses)."""
    follower, params = PathFollower(FollowerParams()), FootprintParams()
    body, bare = body_points(params), body_points(FootprintParams(margin_m=0.0))
    x, y, theta = start
    refused, poses = 0, [start]
    for _ in range(steps):
        pose = (x, y, theta)
        clear = clear_of_walls(grid, pose, params, body) if check else None
        v, w, done = follower.command(pose, np.array(path), DT, clear=clear, nearer_m=params.lookaheads_m,
                                      creep_mps=params.creep_mps)
        if done:
            return True, refused, poses
        nxt = (x + v * DT * math.cos(theta), y + v * DT * math.sin(theta), theta + w * DT)
        if wall_counts(grid, np.array(nxt), bare)[0] > 0:
            refused += 1
            continue
        x, y, theta = nxt
        poses.append(nxt)
    return False, refused, poses


@pytest.mark.parametrize("heading_deg", [-90.0, -120.0, -150.0])
def test_a_robot_off_a_doors_line_goes_through_it_rather_than_onto_its_jamb(heading_deg: float) -> None:
    # Traced in campus 23: 0.43 m before a 1 m door and 0.22 m off its centre line, after a stuck recovery.
    # The planned path keeps the robot radius from the jambs: to the door's line, then through.
    grid = grid_with_wall(door_half_m=0.5)
    start = (0.63, -0.22, math.radians(heading_deg))
    path = [(0.63, -0.22), (0.45, 0.0), (-1.5, 0.0)]
    arrived, refused, _ = drive_through(grid, start, path, check=False)
    assert not arrived and refused > 300  # pinned on the jamb for most of the run
    arrived, refused, _ = drive_through(grid, start, path, check=True)
    assert arrived and refused == 0


def test_a_clear_path_is_driven_the_same_with_the_check() -> None:
    grid = grid_with_wall(door_half_m=0.5)
    start, path = (1.5, -0.6, math.pi), [(1.5, -0.6), (0.6, -0.1), (0.1, 0.0), (-1.5, 0.0)]
    checked, free = drive_through(grid, start, path, check=True), drive_through(grid, start, path, check=False)
    assert checked[:2] == (True, 0)
    assert checked == free  # pose for pose


def test_a_robot_that_must_turn_round_in_a_doorway_leaves_it_first() -> None:
    # Traced in office 16: in a 1 m door, 0.17 m off its middle, facing out of it, with its next target behind.
    # Its corners cannot turn there; pinned, ten recoveries in a row ended the trial as wedged.
    grid = grid_with_wall(door_half_m=0.5)
    start = (0.1, -0.17, math.radians(5.0))
    path = [(0.1, -0.17), (-0.6, 0.0), (-1.5, 0.0)]
    arrived, refused, _ = drive_through(grid, start, path, check=False)
    assert not arrived and refused > 300
    arrived, refused, poses = drive_through(grid, start, path, check=True)
    assert arrived and refused == 0
    assert max(p[0] for p in poses) > 0.3  # it crept out of the doorway before it turned
