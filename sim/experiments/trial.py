"""One closed-loop trial: camera -> tags -> abstract map -> planner -> wheels, in pybullet.

:func:`run_trial` builds the world, puts the robot at the start, and runs the
control loop at ``control_hz`` of simulated time until the goal's label is
read, or a cap on simulated time or distance is hit, or exploration is
exhausted. It never waits on anything but the simulator's own steps.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from abstract_map.model import imagined_positions
from sim.mapping.occupancy import OccupancyGrid, OccupancyParams
from sim.navigation.follower import FollowerParams, PathFollower, Recovery, RecoveryParams, StuckDetector, StuckParams
from sim.navigation.navigator import CueEvent, Navigator, NavigatorParams
from sim.navigation.planner import PlannerParams
from sim.navigation.replanner import Replanner, ReplanParams
from sim.navigation.targeting import Target, TargetParams, choose_target
from sim.perception import GeometricParams, make_perception
from sim.perception.laser import LaserParams, laser_angles, scan
from sim.world.data import World, load_world
from sim.world.robot import Robot, RobotParams
from sim.world.scene import build_scene


@dataclass(frozen=True)
class TrialParams:
    """Rates, caps and the per-trial variation a seed draws."""

    control_hz: float = 10.0  # Hz of simulated time: planning, following, stuck checks
    mapping_hz: float = 5.0  # Hz, laser scans into the occupancy grid
    perception_hz: float = 4.0  # Hz, camera sweeps (or geometric checks)
    max_sim_s: float = 900.0  # s of simulated time before the trial fails
    max_distance_m: float = 300.0  # m travelled before the trial fails
    start_jitter_m: float = 0.0  # m, std of the start position's Gaussian jitter
    start_jitter_deg: float = 0.0  # deg, std of the start heading's jitter
    odometry_noise_m: float = 0.0  # m per sqrt(m travelled), odometry drift (RobotParams); 0 = perfect
    detection_noise_m: float = 0.0  # m, std added to each sighting's position (geometric mode)
    detection_noise_deg: float = 0.0  # deg, std added to each sighting's facing (geometric mode)
    trajectory_hz: float = 2.0  # Hz of the recorded trajectory
    record_every_s: float = 2.0  # s of simulated time between animation frames (with record=True)
    navigator: NavigatorParams = field(default_factory=NavigatorParams)
    # An imagined goal beyond a wall leads to the nearest reachable cell within 10 m of it.
    planner: PlannerParams = field(default_factory=lambda: PlannerParams(goal_snap_radius_m=10.0))
    replan: ReplanParams = field(default_factory=ReplanParams)
    follower: FollowerParams = field(default_factory=FollowerParams)
    targeting: TargetParams = field(default_factory=TargetParams)
    target_recheck_s: float = 5.0  # s between re-choosing the target when the model has not changed
    laser: LaserParams = field(default_factory=LaserParams)
    occupancy_resolution_m: float = 0.1  # m, grid cell


@dataclass(frozen=True)
class Frame:
    """A snapshot for the animation."""

    t_s: float
    pose: tuple[float, float, float]
    grid: np.ndarray  # to_image() of the occupancy grid
    places: dict[str, tuple[float, float]]
    target: tuple[float, float]
    path: np.ndarray | None


@dataclass
class TrialResult:
    """What a trial did, in the form written to result.json."""

    world: str
    goal: str
    seed: int
    perception: str
    success: bool
    reason: str
    distance_m: float
    sim_s: float
    wall_s: float
    start: tuple[float, float, float]
    cues: list[CueEvent]
    trajectory: np.ndarray  # (N, 4): t s, x m, y m, theta rad (true pose)
    final_positions: dict[str, tuple[float, float]]
    exploration_bumps: int
    settle_median_ms: float
    frames: list[Frame] = field(default_factory=list, repr=False)
    grid_extent: tuple[float, float, float, float] | None = None

    @property
    def realtime_factor(self) -> float:
        """Simulated seconds per wall second."""
        return self.sim_s / self.wall_s if self.wall_s > 0 else math.inf

    def to_dict(self) -> dict[str, Any]:
        return {
            "world": self.world, "goal": self.goal, "seed": self.seed, "perception": self.perception,
            "success": self.success, "reason": self.reason, "distance_m": round(self.distance_m, 3),
            "sim_s": round(self.sim_s, 2), "wall_s": round(self.wall_s, 2),
            "realtime_factor": round(self.realtime_factor, 2), "start": list(self.start),
            "cues": [asdict(c) for c in self.cues],
            "exploration_bumps": self.exploration_bumps, "settle_median_ms": round(self.settle_median_ms, 2),
            "final_positions": {k: [round(v[0], 3), round(v[1], 3)] for k, v in self.final_positions.items()},
            "trajectory": [[round(float(v), 3) for v in row] for row in self.trajectory],
        }


Progress = Callable[[float, float, int], None]
"""Called about once per simulated second with (sim time s, distance m, cues read)."""


def _start_pose(world: World, params: TrialParams, rng: np.random.Generator) -> tuple[float, float, float]:
    x, y, theta = world.start
    return (x + rng.normal(0.0, params.start_jitter_m) if params.start_jitter_m else x,
            y + rng.normal(0.0, params.start_jitter_m) if params.start_jitter_m else y,
            theta + math.radians(rng.normal(0.0, params.start_jitter_deg)) if params.start_jitter_deg else theta)


def run_trial(world: World | str, goal: str, *, seed: int = 0, perception: str = "camera",
              params: TrialParams | None = None, progress: Progress | None = None,
              record: bool = False) -> TrialResult:
    """Run one trial of finding ``goal`` in ``world`` and report what happened."""
    began = time.perf_counter()
    world = load_world(world) if isinstance(world, str) else world
    params = params or TrialParams()
    if goal not in world.goals and not world.label_tags(goal):
        raise ValueError(f"goal {goal!r}: no label in world {world.name!r}; study goals: {sorted(world.goals)}")
    rng = np.random.default_rng(seed)
    start = _start_pose(world, params, rng)
    scene = build_scene(world)
    try:
        return _loop(world, goal, scene, start, rng, seed, perception, params, progress, record, began)
    finally:
        scene.close()


def _loop(world: World, goal: str, scene: Any, start: tuple[float, float, float], rng: np.random.Generator,
          seed: int, mode: str, params: TrialParams, progress: Progress | None, record: bool,
          began: float) -> TrialResult:
    robot_params = RobotParams(odometry_noise_m=params.odometry_noise_m)
    robot = Robot(scene, params=robot_params, rng=rng)
    robot.reset(*start)
    sensor = make_perception(mode, scene, rng=rng, **_perception_kwargs(mode, params))
    x0, x1, y0, y1 = world.floorplan.extent
    grid = OccupancyGrid(OccupancyParams(resolution_m=params.occupancy_resolution_m, bounds=(x0, x1, y0, y1)))
    angles = laser_angles(params.laser)
    height = params.laser.height_m

    def cast(origins: np.ndarray, ends: np.ndarray) -> np.ndarray:
        z = np.full((len(origins), 1), height)
        return scene.ray_fractions(np.hstack([origins, z]), np.hstack([ends, z]))

    nav = Navigator.start(world, goal, start, params=params.navigator)
    replanner = Replanner(params.replan, params.planner)
    follower = PathFollower(params.follower)
    stuck, recovery = StuckDetector(StuckParams()), Recovery(RecoveryParams())

    tick = 1.0 / params.control_hz
    steps_per_tick = max(1, round(tick / scene.time_step))
    tick = steps_per_tick * scene.time_step
    every = {name: max(1, round(params.control_hz / hz)) for name, hz in
             (("map", params.mapping_hz), ("see", params.perception_hz), ("traj", params.trajectory_hz))}
    frame_every = max(1, round(params.record_every_s / tick))
    t, distance, n, bumps = 0.0, 0.0, 0, 0
    last = robot.true_pose()
    trajectory = [(0.0, *last)]
    frames: list[Frame] = []
    reason = ""
    target: Target | None = None
    target_at = -math.inf

    def snapshot(pose: tuple[float, float, float]) -> Frame:
        shown = nav.target() if target is None else target.xy
        return Frame(t, pose, grid.to_image(), dict(imagined_positions(nav.model)), tuple(shown),
                     None if replanner.plan is None else replanner.plan.waypoints)

    while True:
        pose = robot.pose()
        if n % every["map"] == 0:
            grid.integrate(pose, angles, scan(pose, cast, params.laser, rng), params.laser.max_range_m)
        if n % every["see"] == 0:
            if nav.observe(sensor.observe(robot), t_s=t, distance_m=distance, explored_centre=grid.explored_centre):
                target = None
            if nav.succeeded:
                reason = "goal label read"
                break
        if t >= params.max_sim_s:
            reason = f"simulated time cap of {params.max_sim_s:.0f} s reached"
            break
        if distance >= params.max_distance_m:
            reason = f"distance cap of {params.max_distance_m:.0f} m reached"
            break
        # A stand-in target is kept until the model changes; the imagined goal is re-checked as the map grows.
        if target is None or (not target.local and t - target_at >= params.target_recheck_s):
            detours = nav.bumps_in_a_row >= params.targeting.local_bumps
            robot_xy = np.array(pose[:2])
            target = choose_target(grid, robot_xy, nav.target(robot_xy), params.planner, params.targeting,
                                   allow_detours=detours)
            target_at = t
        v = w = 0.0
        if recovery.active:
            step = recovery.step(t)
            v, w = step.v, step.w
            if step.replan:
                replanner.request()
                stuck.reset()
        else:
            plan = replanner.update(t, grid, pose[:2], target.xy)
            arrived = plan is None
            if plan is not None:
                v, w, done = follower.command(pose, plan.waypoints, tick)
                arrived = done and float(np.hypot(*(np.array(plan.goal_xy) - pose[:2]))) < nav.params.arrive_m
                if stuck.update(t, pose, commanded=abs(v) > 0.01 or abs(w) > 0.01):
                    recovery.start(t, turn_sign=1.0 if rng.random() < 0.5 else -1.0)
            if arrived:
                if not nav.arrived_without_goal(grid.explored_centre()):
                    reason = "exploration exhausted: the goal was not found where imagined"
                    break
                bumps += 1
                target = None
                replanner.request()
        robot.command(v, w)
        scene.step(steps_per_tick)
        t += tick
        n += 1
        now = robot.true_pose()
        distance += math.hypot(now[0] - last[0], now[1] - last[1])
        last = now
        if n % every["traj"] == 0:
            trajectory.append((t, *now))
        if progress and n % round(1.0 / tick) == 0:
            progress(t, distance, len(nav.cues))
        if record and n % frame_every == 0:
            frames.append(snapshot(now))
    trajectory.append((t, *robot.true_pose()))
    if record:
        frames.append(snapshot(robot.true_pose()))
    if progress:
        progress(t, distance, len(nav.cues))
    settle_ms = [s.wall_s * 1000 for s in nav.settles[1:]] or [nav.settles[0].wall_s * 1000]
    return TrialResult(
        world=world.name, goal=goal, seed=seed, perception=mode, success=nav.succeeded, reason=reason,
        distance_m=distance, sim_s=t, wall_s=time.perf_counter() - began, start=start, cues=nav.cues,
        trajectory=np.array(trajectory), final_positions=dict(imagined_positions(nav.model)),
        exploration_bumps=bumps, settle_median_ms=float(np.median(settle_ms)), frames=frames,
        grid_extent=grid.extent,
    )


def _perception_kwargs(mode: str, params: TrialParams) -> dict[str, Any]:
    """Detection noise is added in geometric mode; the camera's noise is its detector's own."""
    if mode == "geometric":
        return {"params": GeometricParams(noise_m=params.detection_noise_m,
                                          noise_rad=math.radians(params.detection_noise_deg))}
    return {}
