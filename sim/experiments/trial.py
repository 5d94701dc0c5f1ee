"""One closed-loop trial: camera -> tags -> abstract map -> planner -> wheels, in pybullet.

:class:`Trial` builds the world, puts the robot at the start, and steps the
control loop at ``control_hz`` of simulated time until the goal's label is
read, or a cap on simulated time or distance is hit, or exploration is
exhausted; :func:`run_trial` runs one to the end with the navigator driving.
It never waits on anything but the simulator's own steps.
"""

from __future__ import annotations

import logging
import math
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numpy as np

from abstract_map.grammar import Anchor
from sim.experiments.diagnosis import Explanation, ReadingRules, explain, names_place
from sim.experiments.walk import walk_marks
from sim.mapping.occupancy import OccupancyGrid, OccupancyParams
from sim.navigation.belief import BeliefParams
from sim.navigation.follower import FollowerParams
from sim.navigation.gateways import GuideParams
from sim.navigation.names import DEFAULT_NAVIGATOR
from sim.navigation.navigator import CueEvent, NavigatorParams
from sim.navigation.planner import PlannerParams
from sim.navigation.policies import NAVIGATORS, PolicyParams, make_policy
from sim.navigation.replanner import ReplanParams
from sim.navigation.routes import RouteParams
from sim.navigation.spotted import SpottedParams
from sim.navigation.targeting import TargetParams
from sim.navigation.viewpoints import ViewpointParams
from sim.perception import PERCEPTION_MODES, GeometricParams, Sighting, make_perception
from sim.perception.laser import LaserParams, laser_angles, scan
from sim.perception.spotting import SpotParams, Spotter
from sim.world.data import World, load_world
from sim.world.robot import Robot, RobotParams
from sim.world.scene import SceneParams, build_scene

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class TrialParams:
    """Rates, caps and the per-trial variation a seed draws."""

    # Hz of simulated time: planning, following, stuck checks. At its limits the robot moves 8 cm and turns
    # 0.08 rad a tick; halving it from 10 Hz (with the two rates below) cut a zoo trial's CPU by a quarter and
    # left the zoo's distances within their spread (geometric and camera, measured side by side).
    control_hz: float = 5.0
    mapping_hz: float = 2.5  # Hz, laser scans into the occupancy grid: one every 0.16 m at full speed
    perception_hz: float = 2.5  # Hz, camera sweeps (or geometric checks): a tag is in range for ~8 m of corridor
    max_sim_s: float = 900.0  # s of simulated time before the trial fails
    max_distance_m: float = 300.0  # m travelled before the trial fails
    start_jitter_m: float = 0.0  # m, std of the start position's Gaussian jitter
    start_jitter_deg: float = 0.0  # deg, std of the start heading's jitter
    odometry_noise_m: float = 0.0  # m per sqrt(m travelled), odometry drift (RobotParams); 0 = perfect
    detection_noise_m: float = 0.0  # m, std added to each sighting's position (geometric mode)
    detection_noise_deg: float = 0.0  # deg, std added to each sighting's facing (geometric mode)
    trajectory_hz: float = 2.5  # Hz of the recorded trajectory (a whole number of control ticks)
    record_every_s: float = 2.0  # s of simulated time between animation frames (with record=True)
    navigator: NavigatorParams = field(default_factory=NavigatorParams)
    # An imagined goal beyond a wall leads to the nearest reachable cell within 10 m of it.
    planner: PlannerParams = field(default_factory=lambda: PlannerParams(goal_snap_radius_m=10.0))
    replan: ReplanParams = field(default_factory=ReplanParams)
    follower: FollowerParams = field(default_factory=FollowerParams)
    targeting: TargetParams = field(default_factory=TargetParams)
    target_recheck_s: float = 5.0  # s between re-choosing the target when the model has not changed
    belief: BeliefParams = field(default_factory=BeliefParams)  # the viewpoint navigator's goal belief and sweep
    viewpoints: ViewpointParams = field(default_factory=ViewpointParams)  # ... and how it values viewpoints
    routes: RouteParams = field(default_factory=RouteParams)  # ... and what arrows say of where the goal is
    guide: GuideParams = field(default_factory=GuideParams)  # the guided search's trade of path against evidence
    spotted: SpottedParams = field(default_factory=SpottedParams)  # ... and how it uses plates seen, unread
    spotting: SpotParams = field(default_factory=SpotParams)  # when a tag is seen to be there, unread
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
    layers: dict[str, np.ndarray] = field(default_factory=dict)  # uint8 (0-255) images on the grid, e.g. belief


@dataclass(frozen=True)
class Reading:
    """The moment a watched goal's label was first read."""

    t_s: float  # s of simulated time
    distance_m: float  # m driven by then
    wall_s: float  # s of wall time since the trial began
    cpu_s: float  # s of this process's CPU time since the trial began
    trajectory_len: int  # trajectory samples recorded by then
    pose: tuple[float, float, float]  # true pose then (m, m, rad)


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
    navigator: str = DEFAULT_NAVIGATOR  # the navigation policy's name (sim.navigation.policies.NAVIGATORS)
    cpu_s: float = math.nan  # s of this process's CPU time: unlike wall time, not stretched by a busy machine
    unsettled: int = 0  # settles of the abstract map stopped by its step cap (DynamicsParams.max_iterations)
    explanation: str = ""  # a failure's "kind: particulars" (sim.experiments.diagnosis); "" for a success
    near_at_m: float | None = None  # m walked when first near the goal's label (sim.experiments.walk); None: never
    seen_at_m: float | None = None  # m walked when the goal's label was first seen, unread; None: never

    @property
    def realtime_factor(self) -> float:
        """Simulated seconds per wall second."""
        return self.sim_s / self.wall_s if self.wall_s > 0 else math.inf

    def to_dict(self) -> dict[str, Any]:
        return {
            "world": self.world, "goal": self.goal, "seed": self.seed, "perception": self.perception,
            "navigator": self.navigator,
            "success": self.success, "reason": self.reason, "distance_m": round(self.distance_m, 3),
            "sim_s": round(self.sim_s, 2), "wall_s": round(self.wall_s, 2), "cpu_s": round(self.cpu_s, 2),
            "realtime_factor": round(self.realtime_factor, 2), "start": list(self.start),
            "cues": [asdict(c) for c in self.cues],
            "exploration_bumps": self.exploration_bumps, "settle_median_ms": round(self.settle_median_ms, 2),
            "unsettled": self.unsettled, "explanation": self.explanation,
            "near_at_m": _rounded(self.near_at_m), "seen_at_m": _rounded(self.seen_at_m),
            "final_positions": {k: [round(v[0], 3), round(v[1], 3)] for k, v in self.final_positions.items()},
            "trajectory": [[round(float(v), 3) for v in row] for row in self.trajectory],
        }


Progress = Callable[[float, float, int], None]
"""Called about once per simulated second with (sim time s, distance m, cues read)."""


def _rounded(value: float | None, digits: int = 2) -> float | None:
    """``value`` rounded for a record, None kept."""
    return None if value is None else round(value, digits)


def _start_pose(world: World, params: TrialParams, rng: np.random.Generator) -> tuple[float, float, float]:
    x, y, theta = world.start
    return (x + rng.normal(0.0, params.start_jitter_m) if params.start_jitter_m else x,
            y + rng.normal(0.0, params.start_jitter_m) if params.start_jitter_m else y,
            theta + math.radians(rng.normal(0.0, params.start_jitter_deg)) if params.start_jitter_deg else theta)


def occupancy_grid(world: World, params: TrialParams) -> OccupancyGrid:
    """An empty occupancy grid over the world's floor plan (every cell unknown)."""
    x0, x1, y0, y1 = world.floorplan.extent
    return OccupancyGrid(OccupancyParams(resolution_m=params.occupancy_resolution_m, bounds=(x0, x1, y0, y1)))


def policy_params(params: TrialParams) -> PolicyParams:
    """The slice of the trial's parameters a navigation policy is built from."""
    return PolicyParams(params.navigator, params.planner, params.replan, params.follower, params.targeting,
                        params.target_recheck_s, params.belief, params.viewpoints, params.routes,
                        params.guide, params.spotted)


Observer = Callable[["Trial"], None]
"""Called after every control tick with the trial (for recordings); must not change it."""


class Trial:
    """One closed-loop trial, stepped one control tick at a time.

    Construction builds the world, puts the robot at the (jittered) start and
    takes the first look (laser and tags at t = 0). Each :meth:`step` drives
    for one tick with the given ``(v, w)`` command (m/s, rad/s; the robot's
    limits apply) or, without one, with the navigator's own command, then
    senses at the rates in :class:`TrialParams`. :attr:`done` turns true when
    the goal's label is read, a cap is hit or exploration is exhausted, with
    :attr:`reason` saying which. Always :meth:`close` it (or use ``with``).

    ``also`` names further goals to watch for a navigator that never reads a
    sign (``goal_blind``): its path does not depend on the goal, so one run
    that goes on until every watched label is read stands for one trial per
    goal (:meth:`results`), exactly as separate runs with the same seed.
    """

    def __init__(self, world: World | str | os.PathLike[str], goal: str, *, seed: int = 0, perception: str = "camera",
                 navigator: str = DEFAULT_NAVIGATOR, params: TrialParams | None = None,
                 progress: Progress | None = None, record: bool = False, also: Sequence[str] = ()) -> None:
        self.began = time.perf_counter()
        self.began_cpu = time.process_time()
        self.world = world if isinstance(world, World) else load_world(world)
        self.params = params = params or TrialParams()
        for name in (goal, *also):
            if name not in self.world.goals and not self.world.label_tags(name):
                raise ValueError(f"goal {name!r}: no label in world {self.world.name!r}; "
                                 f"study goals: {sorted(self.world.goals)}")
        if also and not getattr(NAVIGATORS.get(navigator), "goal_blind", False):
            raise ValueError(f"navigator {navigator!r} reads signs, so its path depends on the goal: "
                             "one run cannot stand for several goals")
        self.goal, self.seed, self.mode = goal, seed, perception
        self.progress, self.record = progress, record
        self.observers: list[Observer] = []
        self.rng = rng = np.random.default_rng(seed)
        self.start = _start_pose(self.world, params, rng)
        renders = getattr(PERCEPTION_MODES.get(perception), "renders", True)  # skip the looks when nothing renders
        self.scene = scene = build_scene(self.world, params=SceneParams(visuals=renders))
        try:
            self.robot = Robot(scene, params=RobotParams(odometry_noise_m=params.odometry_noise_m), rng=rng)
            self.robot.reset(*self.start)
            self.sensor = make_perception(perception, scene, rng=rng, **_perception_kwargs(perception, params))
            # plates seen from afar, unread: spotted only for a navigator that takes them in
            uses_spots = getattr(NAVIGATORS.get(navigator), "spots", False)
            self.spotter = Spotter(scene, params.spotting) if uses_spots else None
        except BaseException:
            scene.close()
            raise
        self.grid = occupancy_grid(self.world, params)
        self.angles = laser_angles(params.laser)
        self.navigator = navigator
        self.policy = make_policy(navigator, self.world, goal, self.start, policy_params(params))
        self.watched = {name: {tag.id for tag in self.world.tags.values()
                               if tag.kind == "label" and tag.text.casefold() == name.casefold()}
                        for name in dict.fromkeys((goal, *also))}
        self.goal_tags = self.watched[goal]
        self.readings: dict[str, Reading] = {}  # watched goal -> when its label was first read
        self.success = False
        self.steps_per_tick = max(1, round(1.0 / params.control_hz / scene.time_step))
        self.tick = self.steps_per_tick * scene.time_step  # s of simulated time per step
        self.every = {name: max(1, round(params.control_hz / hz)) for name, hz in
                      (("map", params.mapping_hz), ("see", params.perception_hz), ("traj", params.trajectory_hz))}
        self.frame_every = max(1, round(params.record_every_s / self.tick))
        self.t, self.distance, self.n = 0.0, 0.0, 0
        self.last = self.robot.true_pose()
        self.trajectory: list[tuple[float, float, float, float]] = [(0.0, *self.last)]
        self.frames: list[Frame] = []
        self.reason = ""
        self.scan: np.ndarray | None = None  # m, the latest laser ranges
        self.sightings: list[Sighting] = []  # the tags read at the latest look
        self._sense()

    @property
    def done(self) -> bool:
        return bool(self.reason)

    def __enter__(self) -> Trial:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self.scene.close()

    def _cast(self, origins: np.ndarray, ends: np.ndarray) -> np.ndarray:
        z = np.full((len(origins), 1), self.params.laser.height_m)
        return self.scene.ray_fractions(np.hstack([origins, z]), np.hstack([ends, z]))

    def _sense(self) -> None:
        """Laser and tags at their rates, then the success and cap checks."""
        params, pose = self.params, self.robot.pose()
        self.sightings = []
        if self.n % self.every["map"] == 0:
            self.scan = scan(pose, self._cast, params.laser, self.rng)
            self.grid.integrate(pose, self.angles, self.scan, params.laser.max_range_m)
        if self.n % self.every["see"] == 0:
            self.sightings = self.sensor.observe(self.robot)
            self.policy.observe(self.sightings, t_s=self.t, distance_m=self.distance, grid=self.grid,
                                spotted=() if self.spotter is None else self.spotter.spot(self.robot))
            seen = {s.tag_id for s in self.sightings}
            for name, tags in self.watched.items():
                if name not in self.readings and tags & seen:
                    self.readings[name] = Reading(self.t, self.distance, time.perf_counter() - self.began,
                                                  time.process_time() - self.began_cpu, len(self.trajectory),
                                                  self.robot.true_pose())
            if len(self.readings) == len(self.watched):
                self.success = True
                self.reason = "goal label read"
                return
        if self.t >= params.max_sim_s:
            self.reason = f"simulated time cap of {params.max_sim_s:.0f} s reached"
        elif self.distance >= params.max_distance_m:
            self.reason = f"distance cap of {params.max_distance_m:.0f} m reached"

    def command(self) -> tuple[float, float]:
        """The navigator's own (v, w) for this tick (m/s, rad/s); may end the trial (the navigator gave up)."""
        v, w = self.policy.command(self.t, self.robot.pose(), self.grid, self.tick, self.rng)
        if self.policy.gave_up:
            self.reason = self.policy.gave_up
        return v, w

    def step(self, command: tuple[float, float] | None = None) -> bool:
        """Drive one tick with ``command`` (m/s, rad/s) or the navigator's own; sense. True when done."""
        if self.done:
            raise RuntimeError(f"trial already ended: {self.reason}")
        v, w = self.command() if command is None else command
        if self.done:
            return True
        self.robot.command(v, w)
        self.scene.step(self.steps_per_tick)
        self.t += self.tick
        self.n += 1
        now = self.robot.true_pose()
        self.distance += math.hypot(now[0] - self.last[0], now[1] - self.last[1])
        self.last = now
        if self.n % self.every["traj"] == 0:
            self.trajectory.append((self.t, *now))
        if self.progress and self.n % round(1.0 / self.tick) == 0:
            self.progress(self.t, self.distance, len(self.policy.cues))
        if self.record and self.n % self.frame_every == 0:
            self.frames.append(self.snapshot(now))
        self._sense()
        for observer in self.observers:
            observer(self)
        return self.done

    def snapshot(self, pose: tuple[float, float, float]) -> Frame:
        """An animation frame of the trial now."""
        places, target, path = self.policy.picture()
        layers = getattr(self.policy, "layers", dict)()
        images = {name: np.round(255 * np.clip(image, 0.0, 1.0)).astype(np.uint8) for name, image in layers.items()}
        return Frame(self.t, pose, self.grid.to_image(), places, target, path, images)

    def result(self) -> TrialResult:
        """What the trial did so far, as written to result.json."""
        final = self.robot.true_pose()
        trajectory = [*self.trajectory, (self.t, *final)]
        frames = [*self.frames, self.snapshot(final)] if self.record else []
        if self.progress:
            self.progress(self.t, self.distance, len(self.policy.cues))
        settles = self.policy.settles()
        settle_ms = [s.wall_s * 1000 for s in settles[1:] or settles]  # the first settle places the whole hierarchy
        marks = walk_marks(self.world, self.goal, np.array(trajectory), self.distance, spot=self.params.spotting)
        return TrialResult(
            world=self.world.name, goal=self.goal, seed=self.seed, perception=self.mode, success=self.success,
            reason=self.reason, distance_m=self.distance, sim_s=self.t, wall_s=time.perf_counter() - self.began,
            start=self.start, cues=self.policy.cues, trajectory=np.array(trajectory),
            final_positions=self.policy.picture()[0], exploration_bumps=getattr(self.policy, "bumps", 0),
            settle_median_ms=float(np.median(settle_ms)) if settle_ms else 0.0, frames=frames,
            grid_extent=self.grid.extent, navigator=self.navigator, cpu_s=time.process_time() - self.began_cpu,
            unsettled=sum(not s.settled for s in settles),
            explanation="" if self.success else str(self.explain(self.goal, np.array(trajectory))),
            near_at_m=marks.near_at_m, seen_at_m=marks.seen_at_m,
        )


    def results(self) -> dict[str, TrialResult]:
        """Per watched goal, the result a trial of that goal alone would have given: the run up to its label's
        first read, or the whole run when it was never read."""
        result = self.result()
        out = {}
        for goal in self.watched:
            reading = self.readings.get(goal)
            if reading is None:
                marks = walk_marks(self.world, goal, result.trajectory, result.distance_m, spot=self.params.spotting)
                out[goal] = replace(result, goal=goal, success=False,
                                    explanation=str(self.explain(goal, result.trajectory)),
                                    near_at_m=marks.near_at_m, seen_at_m=marks.seen_at_m)
                continue
            trajectory = np.array([*self.trajectory[:reading.trajectory_len], (reading.t_s, *reading.pose)])
            marks = walk_marks(self.world, goal, trajectory, reading.distance_m, spot=self.params.spotting)
            out[goal] = replace(result, goal=goal, success=True, reason="goal label read",
                                near_at_m=marks.near_at_m, seen_at_m=marks.seen_at_m,
                                distance_m=reading.distance_m, sim_s=reading.t_s, wall_s=reading.wall_s,
                                cpu_s=reading.cpu_s, trajectory=trajectory,
                                frames=[f for f in result.frames if f.t_s <= reading.t_s], explanation="")
        return out

    def explain(self, goal: str, trajectory: np.ndarray) -> Explanation:
        """Why ``goal``'s label was not read along ``trajectory`` (rows t s, x m, y m, theta rad: the true pose),
        by the perception's reading rules from where the camera was, and what the navigator knew."""
        sensor = getattr(self.sensor, "params", None)  # both perception modes state their reading rules
        rules = ReadingRules(**{name: getattr(sensor, name) for name in ("max_range_m", "cone_half_angle_deg")
                                if hasattr(sensor, name)})
        x, y, z, _ = self.robot.camera_pose()
        bx, by, heading = self.robot.true_pose()
        ahead = complex(x - bx, y - by) * complex(math.cos(-heading), math.sin(-heading))  # camera in the robot frame
        poses = np.asarray(trajectory, dtype=float).reshape(-1, 4)
        cameras = poses[:, 1] + 1j * poses[:, 2] + ahead * np.exp(1j * poses[:, 3])
        faces = [self.scene.tag_poses[tag] for tag in sorted(self.watched[goal])]
        stop = getattr(sensor, "ray_stop_m", GeometricParams().ray_stop_m)

        def sight(points: np.ndarray, label: int) -> np.ndarray:
            face = faces[label]
            end = [face.x + stop * math.cos(face.theta), face.y + stop * math.sin(face.theta), face.z]
            origins = np.column_stack([points, np.full(len(points), z)])
            return self.scene.ray_fractions(origins, np.tile(end, (len(points), 1))) >= 1.0

        imagined = {name.casefold(): xy for name, xy in self.policy.picture()[0].items()}.get(goal.casefold())
        return explain(poses[:, 0], np.column_stack([cameras.real, cameras.imag]),
                       [(f.x, f.y, f.theta) for f in faces], rules=rules, sight=sight,
                       named=None if getattr(NAVIGATORS.get(self.navigator), "goal_blind", False)
                       else self._named(goal),
                       imagined=None if imagined is None else (float(imagined[0]), float(imagined[1])))

    def _named(self, goal: str) -> bool:
        """Whether a sign the navigator read names ``goal``."""
        signs = [(cue.text, self.world.tags[cue.tag_id]) for cue in self.policy.cues
                 if cue.tag_id in self.world.tags and self.world.tags[cue.tag_id].kind != "label"]
        return any(names_place(text, Anchor(f"#{tag.id}", tag.x, tag.y, tag.theta), goal) for text, tag in signs)


def run_trial(world: World | str | os.PathLike[str], goal: str, *, seed: int = 0, perception: str = "camera",
              navigator: str = DEFAULT_NAVIGATOR, params: TrialParams | None = None, progress: Progress | None = None,
              record: bool = False, log: str | os.PathLike[str] | None = None) -> TrialResult:
    """Run one trial of finding ``goal`` in ``world`` with the navigator driving, and report what happened.

    ``log`` names a rerun recording (.rrd) to write on the simulated-time line (needs the ``viz`` extra;
    see :mod:`sim.experiments.recording`).
    """
    with Trial(world, goal, seed=seed, perception=perception, navigator=navigator, params=params,
               progress=progress, record=record) as trial:
        recorder = None
        if log is not None:
            from sim.experiments.recording import Recorder

            recorder = Recorder(trial, log)
            trial.observers.append(recorder)
        try:
            while not trial.done:
                trial.step()
            result = trial.result()
        except BaseException:
            if recorder is not None:
                recorder.abandon()
            raise
        if recorder is not None:
            recorder.close(result)
        if result.unsettled:
            logger.warning("%s, %s: %d settle(s) of the abstract map stopped at the step cap with places still "
                           "moving", result.world, result.goal, result.unsettled)
        return result


def _perception_kwargs(mode: str, params: TrialParams) -> dict[str, Any]:
    """Detection noise is added in geometric mode; the camera's noise is its detector's own."""
    if mode == "geometric":
        return {"params": GeometricParams(noise_m=params.detection_noise_m,
                                          noise_rad=math.radians(params.detection_noise_deg))}
    return {}
