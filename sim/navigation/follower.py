"""Following a waypoint polyline with a differential-drive robot, and getting unstuck.

Frames: world frame, metres, radians counter-clockwise from +x. Commands
are (v m/s forward, w rad/s counter-clockwise). Nothing here touches a
simulator: the caller feeds poses and times in and applies the commands.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from sim.world.pose import check_pose


def wrap_angle(angle: float) -> float:
    """``angle`` (rad) wrapped to [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


@dataclass(frozen=True)
class FollowerParams:
    """Pure-pursuit follower with turn-in-place and a slow approach to the goal."""

    max_speed: float = 0.4  # m/s
    max_turn: float = 0.4  # rad/s
    lookahead_m: float = 0.8  # m along the path from the robot's nearest point to the carrot
    goal_tolerance_m: float = 0.3  # m from the final waypoint that counts as arrived
    turn_in_place_rad: float = math.radians(60.0)  # rad; heading error beyond which the robot only turns
    turn_gain: float = 1.5  # (rad/s) per rad of heading error when turning in place
    slowdown_m: float = 1.0  # m from the goal where the speed starts to fall linearly
    min_speed: float = 0.05  # m/s floor of the approach speed, so the robot still arrives
    max_accel: float | None = None  # m/s^2 limit on changes of v, when command() gets dt_s
    max_turn_accel: float | None = None  # rad/s^2 limit on changes of w, when command() gets dt_s

    def __post_init__(self) -> None:
        for name in ("max_speed", "max_turn", "lookahead_m", "goal_tolerance_m", "turn_in_place_rad",
                     "turn_gain", "slowdown_m"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"FollowerParams.{name} must be finite and > 0, got {value}")
        if not (0 <= self.min_speed <= self.max_speed):
            raise ValueError(f"FollowerParams.min_speed must be in [0, max_speed], got {self.min_speed}")
        for name in ("max_accel", "max_turn_accel"):
            value = getattr(self, name)
            if value is not None and not (math.isfinite(value) and value > 0):
                raise ValueError(f"FollowerParams.{name} must be None or finite and > 0, got {value}")

    def turn_in_place(self, error_rad: float) -> float:
        """The turn rate (rad/s) that turns in place against a heading error (rad): ``turn_gain`` times it,
        capped at ``max_turn``."""
        return float(np.clip(self.turn_gain * error_rad, -self.max_turn, self.max_turn))


def _check_waypoints(waypoints: np.ndarray) -> np.ndarray:
    pts = np.asarray(waypoints, dtype=float)
    if pts.ndim == 1 and pts.size == 2:
        pts = pts[None, :]
    if pts.ndim != 2 or pts.shape[1] != 2 or not np.all(np.isfinite(pts)):
        raise ValueError(f"waypoints must be a finite (N, 2) array in metres, got shape {pts.shape}")
    return pts


def carrot(position: np.ndarray, waypoints: np.ndarray, lookahead_m: float) -> np.ndarray:
    """The point ``lookahead_m`` further along the polyline than its point nearest ``position`` (m)."""
    pts = _check_waypoints(waypoints)
    if len(pts) == 1:
        return pts[0].copy()
    a, b = pts[:-1], pts[1:]
    ab = b - a
    seg_len = np.hypot(ab[:, 0], ab[:, 1])
    s = np.clip(np.sum((position - a) * ab, axis=1) / np.maximum(seg_len ** 2, 1e-12), 0.0, 1.0)
    nearest = a + s[:, None] * ab
    k = int(np.argmin(np.hypot(*(nearest - position).T)))
    cumulative = np.concatenate([[0.0], np.cumsum(seg_len)])
    target = min(cumulative[k] + s[k] * seg_len[k] + lookahead_m, cumulative[-1])
    j = int(np.clip(np.searchsorted(cumulative, target, side="right") - 1, 0, len(seg_len) - 1))
    frac = 0.0 if seg_len[j] == 0 else (target - cumulative[j]) / seg_len[j]
    return a[j] + min(frac, 1.0) * ab[j]


class PathFollower:
    """Pure pursuit towards a carrot on the path; turns in place when facing away from it.

    Stateless except for the last command, used only for the optional
    acceleration limits (call :meth:`reset` when starting a new run).
    """

    def __init__(self, params: FollowerParams = FollowerParams()) -> None:
        self.params = params
        self._last = (0.0, 0.0)

    def reset(self) -> None:
        """Forget the last command (acceleration limits start from rest)."""
        self._last = (0.0, 0.0)

    def command(self, pose: tuple[float, float, float] | np.ndarray, waypoints: np.ndarray,
                dt_s: float | None = None, clear: Callable[[float, float], bool] | None = None,
                nearer_m: Sequence[float] = (), creep_mps: float = 0.0) -> tuple[float, float, bool]:
        """(v m/s, w rad/s, done) to follow ``waypoints`` (N, 2, m) from ``pose`` (x m, y m, theta rad).

        ``done`` is True, with a zero command, once the robot is within
        ``goal_tolerance_m`` of the last waypoint. ``dt_s`` (s since the
        last command) enables the acceleration limits when they are set;
        the stop on arrival is not rate-limited (the approach is already slow).

        ``clear(v, w)`` says whether a command may be driven (the caller's
        map: :func:`sim.navigation.footprint.clear_of_walls`). When the command for
        the carrot ``lookahead_m`` on is not, the first clear one of these is
        taken: the commands for the carrots ``nearer_m`` (m, in turn), then
        ``creep_mps`` straight ahead, then as fast straight back (when
        ``creep_mps`` > 0). When none is clear the first command stands (the
        stuck recovery then backs the robot off).
        """
        p = self.params
        x, y, theta = check_pose(pose)
        pts = _check_waypoints(waypoints)
        position = np.array([x, y])
        to_goal = float(np.hypot(*(pts[-1] - position)))
        if to_goal <= p.goal_tolerance_m:
            self._last = (0.0, 0.0)
            return 0.0, 0.0, True
        v, w = self._steer(position, theta, pts, to_goal, p.lookahead_m)
        if clear is not None and not clear(v, w):
            creeps = [(creep_mps, 0.0), (-creep_mps, 0.0)] if creep_mps > 0 else []
            others = (self._steer(position, theta, pts, to_goal, lookahead) for lookahead in nearer_m)
            v, w = next((c for c in (*others, *creeps) if clear(*c)), (v, w))
        v, w = self._limit(v, w, dt_s)
        return v, w, False

    def _steer(self, position: np.ndarray, theta: float, pts: np.ndarray, to_goal: float,
               lookahead_m: float) -> tuple[float, float]:
        """(v m/s, w rad/s) towards the carrot ``lookahead_m`` (m) along ``pts`` from ``position``, before limits."""
        p = self.params
        offset = carrot(position, pts, lookahead_m) - position
        distance = float(np.hypot(*offset))
        if distance < 1e-9:  # on the carrot: aim at the goal instead
            offset, distance = pts[-1] - position, to_goal
        alpha = wrap_angle(math.atan2(offset[1], offset[0]) - theta)

        turn_in_place = p.turn_in_place(alpha)
        if abs(alpha) >= p.turn_in_place_rad:
            return 0.0, turn_in_place
        # alignment: 1 when facing the carrot, 0 at the turn-in-place threshold. Speed fades with it
        # (and near the goal) while the turn blends from pure pursuit into turning in place.
        alignment = (math.cos(alpha) - math.cos(p.turn_in_place_rad)) / (1.0 - math.cos(p.turn_in_place_rad))
        approach = max(p.min_speed, p.max_speed * min(1.0, to_goal / p.slowdown_m))
        v = min(p.max_speed, approach) * alignment
        pursuit = v * 2.0 * math.sin(alpha) / distance
        w = alignment * pursuit + (1.0 - alignment) * turn_in_place
        if abs(w) > p.max_turn:  # keep the curvature, slow down instead
            v *= p.max_turn / abs(w)
            w = math.copysign(p.max_turn, w)
        return v, w

    def _limit(self, v: float, w: float, dt_s: float | None) -> tuple[float, float]:
        p = self.params
        if dt_s is not None:
            if not (math.isfinite(dt_s) and dt_s > 0):
                raise ValueError(f"dt_s must be finite and > 0, got {dt_s}")
            last_v, last_w = self._last
            if p.max_accel is not None:
                v = float(np.clip(v, last_v - p.max_accel * dt_s, last_v + p.max_accel * dt_s))
            if p.max_turn_accel is not None:
                w = float(np.clip(w, last_w - p.max_turn_accel * dt_s, last_w + p.max_turn_accel * dt_s))
        v = float(np.clip(v, -p.max_speed, p.max_speed))
        w = float(np.clip(w, -p.max_turn, p.max_turn))
        self._last = (v, w)
        return v, w


@dataclass(frozen=True)
class StuckParams:
    """When a robot that is told to move counts as stuck."""

    window_s: float = 4.0  # s of history judged at once
    min_progress_m: float = 0.1  # m the robot must translate within the window ...
    min_rotation_rad: float = 0.2  # ... or rad it must turn, to count as moving

    def __post_init__(self) -> None:
        for name in ("window_s", "min_progress_m", "min_rotation_rad"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"StuckParams.{name} must be finite and > 0, got {value}")


class StuckDetector:
    """Fires when, over a full window of being commanded to move, the robot barely moved.

    After firing, or whenever the robot is not commanded to move, the window
    starts again.
    """

    def __init__(self, params: StuckParams = StuckParams()) -> None:
        self.params = params
        self._history: deque[tuple[float, float, float, float]] = deque()

    def reset(self) -> None:
        """Forget the history."""
        self._history.clear()

    def update(self, t: float, pose: tuple[float, float, float] | np.ndarray, commanded: bool = True) -> bool:
        """Record ``pose`` (x m, y m, theta rad) at time ``t`` (s); True if stuck.

        ``commanded``: whether a non-zero (v, w) was being sent. Times must not decrease.
        """
        if not math.isfinite(t):
            raise ValueError(f"t must be finite, got {t}")
        x, y, theta = check_pose(pose)
        if self._history and t < self._history[-1][0]:
            raise ValueError(f"t went backwards: {t} after {self._history[-1][0]}")
        if not commanded:
            self._history.clear()
            return False
        self._history.append((t, x, y, theta))
        while len(self._history) > 1 and t - self._history[1][0] >= self.params.window_s:
            self._history.popleft()
        t0 = self._history[0][0]
        if t - t0 < self.params.window_s:
            return False
        samples = np.array(self._history)
        moved = float(np.max(np.hypot(samples[:, 1] - x, samples[:, 2] - y)))
        headings = np.unwrap(samples[:, 3])
        turned = float(np.max(headings) - np.min(headings))
        if moved < self.params.min_progress_m and turned < self.params.min_rotation_rad:
            self._history.clear()
            return True
        return False


@dataclass(frozen=True)
class RecoveryParams:
    """Back off, rotate, then ask for a re-plan."""

    backoff_s: float = 1.0  # s of reversing
    backoff_speed: float = -0.2  # m/s (negative: backwards)
    rotate_rad: float = math.pi / 2  # rad to turn after backing off
    rotate_rate: float = 0.4  # rad/s magnitude of the turn
    max_in_place: int = 10  # recoveries in a row that leave the robot within ``escape_m`` of where the first one
    # began: it is wedged (a body pinned on a wall's end turns no wheel); each takes ~10 s, so ~100 s of trying
    escape_m: float = 0.5  # m the robot must get from where a run of recoveries began for the run to end

    def __post_init__(self) -> None:
        if not (math.isfinite(self.backoff_s) and self.backoff_s >= 0):
            raise ValueError(f"RecoveryParams.backoff_s must be finite and >= 0, got {self.backoff_s}")
        if not (math.isfinite(self.backoff_speed) and self.backoff_speed <= 0):
            raise ValueError(f"RecoveryParams.backoff_speed must be finite and <= 0, got {self.backoff_speed}")
        if not (math.isfinite(self.rotate_rad) and self.rotate_rad >= 0):
            raise ValueError(f"RecoveryParams.rotate_rad must be finite and >= 0, got {self.rotate_rad}")
        if not (math.isfinite(self.rotate_rate) and self.rotate_rate > 0):
            raise ValueError(f"RecoveryParams.rotate_rate must be finite and > 0, got {self.rotate_rate}")
        if self.max_in_place < 1:
            raise ValueError(f"RecoveryParams.max_in_place must be >= 1, got {self.max_in_place}")
        if not (math.isfinite(self.escape_m) and self.escape_m > 0):
            raise ValueError(f"RecoveryParams.escape_m must be finite and > 0, got {self.escape_m}")


def recovery_commands(params: RecoveryParams = RecoveryParams(),
                      turn_sign: float = 1.0) -> list[tuple[str, float, float, float]]:
    """The recovery schedule: (phase, duration s, v m/s, w rad/s) per phase.

    ``turn_sign`` > 0 turns counter-clockwise, < 0 clockwise.
    """
    w = math.copysign(params.rotate_rate, turn_sign if turn_sign != 0 else 1.0)
    return [("backoff", params.backoff_s, params.backoff_speed, 0.0),
            ("rotate", params.rotate_rad / params.rotate_rate, 0.0, w)]


@dataclass(frozen=True)
class RecoveryStep:
    """One tick of :class:`Recovery`."""

    v: float  # m/s
    w: float  # rad/s
    phase: str  # "backoff", "rotate" or "idle"
    replan: bool  # True once, on the tick the manoeuvre ends: the caller should re-plan now


class Recovery:
    """Time-driven recovery manoeuvre: :meth:`start` it, then call :meth:`step` every tick."""

    def __init__(self, params: RecoveryParams = RecoveryParams()) -> None:
        self.params = params
        self._started_at: float | None = None
        self._schedule: list[tuple[str, float, float, float]] = []

    @property
    def active(self) -> bool:
        """Whether a manoeuvre is under way."""
        return self._started_at is not None

    def start(self, t: float, turn_sign: float = 1.0) -> None:
        """Begin a manoeuvre at time ``t`` (s), turning counter-clockwise if ``turn_sign`` > 0."""
        if not (math.isfinite(t) and math.isfinite(turn_sign)):
            raise ValueError(f"Recovery.start: t and turn_sign must be finite, got {t}, {turn_sign}")
        self._started_at = t
        self._schedule = recovery_commands(self.params, turn_sign)

    def step(self, t: float) -> RecoveryStep:
        """The command at time ``t`` (s); idle (zero command) when no manoeuvre is under way."""
        if self._started_at is None:
            return RecoveryStep(0.0, 0.0, "idle", False)
        if not math.isfinite(t):
            raise ValueError(f"Recovery.step: t must be finite, got {t}")
        elapsed = t - self._started_at
        for phase, duration, v, w in self._schedule:
            if elapsed < duration:
                return RecoveryStep(v, w, phase, False)
            elapsed -= duration
        self._started_at = None
        return RecoveryStep(0.0, 0.0, "idle", True)
