"""Path following on a simulated unicycle, stuck detection and recovery."""

import math

import numpy as np
import pytest

from sim.navigation.follower import (
    FollowerParams,
    PathFollower,
    Recovery,
    RecoveryParams,
    StuckDetector,
    StuckParams,
    carrot,
    recovery_commands,
)

DT = 0.1  # s


def drive(follower: PathFollower, pose: tuple[float, float, float], waypoints: np.ndarray,
          max_steps: int = 2000) -> tuple[np.ndarray, np.ndarray, bool]:
    """Integrate a unicycle under the follower's commands; returns poses, commands and done."""
    x, y, theta = pose
    poses, commands = [pose], []
    for _ in range(max_steps):
        v, w, done = follower.command((x, y, theta), waypoints, DT)
        commands.append((v, w))
        if done:
            return np.array(poses), np.array(commands), True
        x += v * math.cos(theta) * DT
        y += v * math.sin(theta) * DT
        theta += w * DT
        poses.append((x, y, theta))
    return np.array(poses), np.array(commands), False


def test_drives_to_the_goal_within_limits_and_tolerance() -> None:
    params = FollowerParams()
    waypoints = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 3.0], [1.0, 5.0]])
    poses, commands, done = drive(PathFollower(params), (0.0, 0.0, 0.0), waypoints)
    assert done
    assert np.hypot(*(poses[-1, :2] - waypoints[-1])) <= params.goal_tolerance_m
    assert np.all(np.abs(commands[:, 0]) <= 0.4 + 1e-12)
    assert np.all(np.abs(commands[:, 1]) <= 0.4 + 1e-12)
    assert commands[:, 0].max() == pytest.approx(0.4)  # it does use its top speed
    # It stays near the polyline (pure pursuit cuts corners by less than the lookahead).
    dense = np.concatenate([a + np.linspace(0, 1, 200)[:, None] * (b - a)
                            for a, b in zip(waypoints[:-1], waypoints[1:])])
    deviation = np.min(np.hypot(*(poses[:, None, :2] - dense[None]).transpose(2, 0, 1)), axis=1)
    assert deviation.max() < params.lookahead_m
    path_length = 4.0 + 3.0 + math.hypot(3.0, 2.0)
    assert len(poses) * DT < 2.0 * path_length / 0.4


def test_turns_in_place_when_facing_away() -> None:
    follower = PathFollower()
    v, w, done = follower.command((0.0, 0.0, math.pi), np.array([[0.0, 0.0], [3.0, 0.0]]))
    assert not done and v == 0.0 and abs(w) == pytest.approx(0.4)
    poses, commands, done = drive(PathFollower(), (0.0, 0.0, math.pi), np.array([[0.0, 0.0], [3.0, 0.0]]))
    assert done
    moving = np.nonzero(commands[:, 0] > 0)[0][0]
    heading_then = poses[moving, 2] % (2 * math.pi)
    assert abs(heading_then - math.pi) > math.radians(100)  # it had turned most of the way first


def test_slows_down_near_the_goal() -> None:
    follower = PathFollower()
    far, _, _ = follower.command((0.0, 0.0, 0.0), np.array([[0.0, 0.0], [5.0, 0.0]]))
    near, _, _ = follower.command((4.4, 0.0, 0.0), np.array([[0.0, 0.0], [5.0, 0.0]]))
    assert far == pytest.approx(0.4)
    assert 0.0 < near < 0.3


def test_done_at_goal_and_single_waypoint() -> None:
    follower = PathFollower()
    assert follower.command((1.0, 1.0, 0.0), np.array([[1.1, 1.1]])) == (0.0, 0.0, True)
    poses, _, done = drive(follower, (0.0, 0.0, 0.5), np.array([[2.0, -1.0]]))
    assert done and np.hypot(poses[-1, 0] - 2.0, poses[-1, 1] + 1.0) <= 0.3


def test_acceleration_limits_are_respected() -> None:
    params = FollowerParams(max_accel=0.5, max_turn_accel=1.0)
    _, commands, done = drive(PathFollower(params), (0.0, 0.0, 0.0), np.array([[0.0, 0.0], [3.0, 1.0]]))
    assert done
    steps = np.diff(np.vstack([[0.0, 0.0], commands]), axis=0)
    assert commands[-1].tolist() == [0.0, 0.0]  # the stop on arrival is immediate ...
    assert np.all(np.abs(steps[:-1, 0]) <= 0.5 * DT + 1e-9)  # ... every other change is rate-limited
    assert np.all(np.abs(steps[:-1, 1]) <= 1.0 * DT + 1e-9)


def test_carrot_is_lookahead_along_the_path() -> None:
    waypoints = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 2.0]])
    assert carrot(np.array([0.2, 0.1]), waypoints, 1.0) == pytest.approx([1.0, 0.2])
    assert carrot(np.array([0.9, 1.5]), waypoints, 5.0) == pytest.approx([1.0, 2.0])


def test_bad_inputs_are_named() -> None:
    with pytest.raises(ValueError, match="pose"):
        PathFollower().command((0.0, 0.0, float("inf")), np.array([[1.0, 1.0]]))
    with pytest.raises(ValueError, match="waypoints"):
        PathFollower().command((0.0, 0.0, 0.0), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="max_speed"):
        FollowerParams(max_speed=0.0)


def test_stuck_detector_fires_when_commanded_robot_does_not_move() -> None:
    detector = StuckDetector(StuckParams(window_s=2.0, min_progress_m=0.1))
    fired = [detector.update(0.1 * k, (1.0, 2.0, 0.3), commanded=True) for k in range(31)]
    assert not any(fired[:20])
    assert fired[20]  # exactly one full window after the first sample
    assert not any(fired[21:40])  # the window starts afresh after firing


def test_stuck_detector_is_quiet_while_moving_or_idle() -> None:
    detector = StuckDetector(StuckParams(window_s=2.0, min_progress_m=0.1))
    assert not any(detector.update(0.1 * k, (0.04 * k, 0.0, 0.0)) for k in range(100))
    assert not any(detector.update(10 + 0.1 * k, (4.0, 0.0, 0.0), commanded=False) for k in range(100))
    turning = [detector.update(20 + 0.1 * k, (4.0, 0.0, 0.04 * k)) for k in range(100)]
    assert not any(turning)


def test_recovery_backs_off_rotates_then_asks_for_a_replan() -> None:
    params = RecoveryParams(backoff_s=1.0, backoff_speed=-0.2, rotate_rad=math.pi / 2, rotate_rate=0.4)
    schedule = recovery_commands(params, turn_sign=-1.0)
    assert schedule[0] == ("backoff", 1.0, -0.2, 0.0)
    assert schedule[1][0] == "rotate" and schedule[1][3] == -0.4
    recovery = Recovery(params)
    assert not recovery.active and recovery.step(0.0).phase == "idle"
    recovery.start(10.0, turn_sign=1.0)
    steps = [recovery.step(10.0 + 0.1 * k) for k in range(60)]
    phases = [s.phase for s in steps]
    assert phases[:10] == ["backoff"] * 10 and all(s.v == -0.2 for s in steps[:10])
    rotating = [s for s in steps if s.phase == "rotate"]
    assert sum(s.w * 0.1 for s in rotating) == pytest.approx(math.pi / 2, abs=0.05)
    replans = [k for k, s in enumerate(steps) if s.replan]
    assert len(replans) == 1 and phases[replans[0]] == "idle"
    assert not recovery.active


def pinned_drive(poses, ticks: int, tick_s: float = 0.2):
    """A DriveStack told to drive to (8, 8) m on an open 10 m x 10 m map while the robot stands at
    ``poses(k)`` at tick ``k``; returns the drive stack and the first tick it said it was wedged (None: never)."""
    from sim.experiments.trial import TrialParams, policy_params
    from sim.mapping.occupancy import OccupancyGrid, OccupancyParams
    from sim.navigation.policies import DriveStack

    grid = OccupancyGrid(OccupancyParams(resolution_m=0.1, bounds=(0.0, 10.0, 0.0, 10.0)))
    grid.log_odds[:] = -2.0  # all mapped free
    drive, rng = DriveStack(policy_params(TrialParams())), np.random.default_rng(0)
    for k in range(ticks):
        drive.drive(k * tick_s, poses(k), grid, np.array([8.0, 8.0]), tick_s, 0.5, rng)
        if drive.wedged:
            return drive, k
    return drive, None


def test_a_robot_that_recoveries_cannot_move_is_wedged_and_says_where() -> None:
    drive, at = pinned_drive(lambda k: (2.0, 2.0, 0.0), ticks=2000)
    params = RecoveryParams()
    assert at is not None and drive.in_place == params.max_in_place
    assert at * 0.2 > 5.0 * params.max_in_place  # ~10 s a recovery: a wedge is called only after long trying
    assert drive.wedged.startswith("wedged at (2.0, 2.0) m: 10 stuck recoveries in a row")


def test_recoveries_that_free_the_robot_do_not_add_up_to_a_wedge() -> None:
    # each run of ~20 s pinned ends with the robot 1 m on: stuck again and again, but never in one place
    drive, at = pinned_drive(lambda k: (1.0 + (k // 100) * 1.0, 2.0, 0.0), ticks=900)
    assert at is None and not drive.wedged and 1 <= drive.in_place < RecoveryParams().max_in_place


def test_a_wedged_robot_ends_the_policy() -> None:
    from sim.navigation.policies import FrontierPolicy

    policy = FrontierPolicy.__new__(FrontierPolicy)
    policy.drive = pinned_drive(lambda k: (2.0, 2.0, 0.0), ticks=2000)[0]
    assert policy.gave_up.startswith("wedged at")
    policy.gave_up = "no frontier left"  # the policy's own reason comes first
    assert policy.gave_up == "no frontier left"


def test_a_command_that_is_not_clear_gives_way_to_nearer_carrots_then_a_creep() -> None:
    path = np.array([[0.0, 0.0], [0.0, 2.0], [-2.0, 2.0]])  # the carrot 0.8 m on lies round the corner
    pose = (0.0, 1.5, math.pi / 2)
    follower = PathFollower()
    own = follower.command(pose, path, DT)
    assert own[0] > 0 and own[1] > 0  # on and left, cutting the corner
    nearer = follower.command(pose, path, DT, clear=lambda v, w: w < own[1], nearer_m=(0.4, 0.2))
    assert 0 <= nearer[1] < own[1]  # a carrot nearer the corner turns less
    creeps = []
    follower.command(pose, path, DT, clear=lambda v, w: creeps.append((v, w)) or v < 0, nearer_m=(0.4, 0.2),
                     creep_mps=0.1)
    assert creeps[-2:] == [(0.1, 0.0), (-0.1, 0.0)]  # both carrots refused, then ahead, then back
    assert follower.command(pose, path, DT, clear=lambda v, w: v < 0, nearer_m=(0.4,), creep_mps=0.1)[:2] == \
        (-0.1, 0.0)
    assert follower.command(pose, path, DT, clear=lambda v, w: False, nearer_m=(0.4,), creep_mps=0.1) == own
