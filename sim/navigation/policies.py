"""Navigation policies: how the robot decides each tick, by name (``--navigator``).

A policy sees what the robot sensed (tag sightings, the occupancy grid, its
pose) and answers with a wheel command ``(v, w)`` (m/s, rad/s). Every policy
shares the same drive stack (re-planner, path follower, stuck recovery); what
differs is where it wants to go. Register a new one in :data:`NAVIGATORS`.

- ``paper``: the paper's robot: drive to the goal's imagined position in the
  abstract map (or a stand-in target when that lies behind walls), grow the
  model when the goal is not there.
- ``frontier``: the no-signs lower bound: reads no sign, drives to the nearest
  reachable frontier (by path length) until the goal's label comes into view,
  and gives up when no frontier is left.
- ``viewpoint``: negative information and readable viewpoints: a belief over
  where the goal's label hangs (the abstract map's imagined goal as its prior,
  ruled out where the camera has swept), driven to the reachable viewpoint that
  reads the most of it per metre; the model grows when the belief near the
  imagined goal is used up, and unswept wall near the robot draws it when the
  cues say little (see ``docs/method-notes.md``).
- ``guided``: a frontier search like ``frontier``'s, reading signs: the frontier
  with the most of that goal belief behind it per metre of path, counted as far
  past it as a walk there pays (:mod:`sim.navigation.gateways`), ruling out
  walls seen from afar without a plate and stepping in front of plates seen but
  unread (:mod:`sim.navigation.spotted`).
- ``even-prior``: ``guided`` with the goal's prior even over the map until
  labels of its siblings are read: the ablation of the abstract map's imagined
  goal.
- ``known-goal``: ``guided`` with the goal's prior on its true label (the
  world's truth): what this search walks when it knows where the goal is but
  not the building, beside ``frontier``'s lower bound.
- ``known-pose``: told where the goal's label hangs and which way it faces,
  drives straight to the space in front of it (unseen space as open,
  re-planned as the map grows): the textbook point-goal planner, the informed
  reference for what a building not yet mapped costs any navigator.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field, replace
from typing import Protocol

import numpy as np

from abstract_map.clauses import Clause, Locational, clause_names, is_anchor, named_by
from abstract_map.model import FixedPoint, SettleReport, imagined_positions
from sim.mapping.occupancy import OccupancyGrid
from sim.navigation.belief import (
    Belief,
    BeliefParams,
    GoalPrior,
    MixedPrior,
    SweptSpace,
    across_ratio,
    cue_mass,
    goal_belief,
    goal_sigma,
)
from sim.navigation.fingerposts import PostTest
from sim.navigation.follower import (
    FollowerParams,
    PathFollower,
    Recovery,
    RecoveryParams,
    StuckDetector,
    StuckParams,
    wrap_angle,
)
from sim.navigation.footprint import FootprintParams, body_points, clear_of_walls
from sim.navigation.frontier import FrontierParams, LookedAt, nearest_frontier, still_frontier
from sim.navigation.gateways import GuideParams, frontier_values
from sim.navigation.navigator import CueEvent, Navigator, NavigatorParams
from sim.navigation.planner import Plan, PlannerParams
from sim.navigation.replanner import Replanner, ReplanParams
from sim.navigation.rooms import RoomParams, other_rooms_likelihood
from sim.navigation.routes import (
    Arrow,
    PathSearches,
    RouteParams,
    door_depth_weight,
    passed_likelihood,
    route_likelihood,
)
from sim.navigation.spotted import SpottedParams, SpottedTags
from sim.navigation.targeting import Target, TargetParams, choose_target
from sim.navigation.viewpoints import ViewpointParams, Viewpoints, score_viewpoints, travel_costs
from sim.perception.sighting import Sighting
from sim.perception.spotting import Spot
from sim.world.data import Tag, World

Pose = tuple[float, float, float]

EVIDENCE_FACTORS = ("doors", "arrows", "unnamed signs", "other rooms")  # the goal evidence's factors, in the
# order they multiply (AbstractMapPolicy.evidence_factors)


@dataclass(frozen=True)
class PolicyParams:
    """What every policy is built from (one slice of the trial's parameters)."""

    navigator: NavigatorParams
    planner: PlannerParams
    replan: ReplanParams
    follower: FollowerParams
    targeting: TargetParams
    target_recheck_s: float  # s between re-choosing the target when nothing new was read
    belief: BeliefParams = field(default_factory=BeliefParams)
    viewpoints: ViewpointParams = field(default_factory=ViewpointParams)
    routes: RouteParams = field(default_factory=RouteParams)
    guide: GuideParams = field(default_factory=GuideParams)
    spotted: SpottedParams = field(default_factory=SpottedParams)
    footprint: FootprintParams = field(default_factory=FootprintParams)
    rooms: RoomParams = field(default_factory=RoomParams)


class Policy(Protocol):
    """What the trial asks of a navigation policy."""

    cues: list[CueEvent]  # tags read for the first time, in order
    gave_up: str  # why the policy stopped (non-empty ends the trial)

    def observe(self, sightings: Iterable[Sighting], *, t_s: float, distance_m: float,
                grid: OccupancyGrid, spotted: Sequence[Spot] = ()) -> None:
        """Take in the tags read now, and the tags seen but not read (:mod:`sim.perception.spotting`)."""

    def command(self, t_s: float, pose: Pose, grid: OccupancyGrid, tick_s: float,
                rng: np.random.Generator) -> tuple[float, float]:
        """The wheel command for the next tick (m/s, rad/s)."""

    def picture(self) -> tuple[dict[str, tuple[float, float]], tuple[float, float], np.ndarray | None]:
        """For drawing: imagined places (m, may be empty), the current target (m) and planned path (N, 2 m)."""

    def settles(self) -> list[SettleReport]:
        """Every settle of the policy's model, in order (empty: no model)."""


class DriveStack:
    """Re-planning, path following and stuck recovery towards a target: the part every policy shares.

    A command that would put the body on a mapped wall is not driven: the follower steers at a nearer
    carrot, or creeps ahead or back, instead (:mod:`sim.navigation.footprint`).

    :attr:`wedged` says why driving is hopeless (empty while it is not): ``RecoveryParams.max_in_place``
    recoveries in a row left the robot where the first began."""

    def __init__(self, params: PolicyParams) -> None:
        self.replanner = Replanner(params.replan, params.planner)
        self.follower = PathFollower(params.follower)
        self.stuck, self.recovery = StuckDetector(StuckParams()), Recovery(RecoveryParams())
        self.footprint = params.footprint
        self.body = body_points(params.footprint)  # the body's sample points, robot frame
        self.in_place = 0  # recoveries in a row within ``escape_m`` of where the run began
        self.run_from: np.ndarray | None = None  # m, where the robot stood when the run's first recovery began
        self.wedged = ""

    @property
    def plan(self) -> Plan | None:
        return self.replanner.plan

    def drive(self, t_s: float, pose: Pose, grid: OccupancyGrid, target_xy: np.ndarray, tick_s: float,
              arrive_m: float, rng: np.random.Generator) -> tuple[float, float, bool]:
        """``(v, w, arrived)``: the command towards ``target_xy``; arrived when within ``arrive_m`` of the plan's end
        or no plan exists (the target cannot be reached)."""
        if self.recovery.active:
            step = self.recovery.step(t_s)
            if step.replan:
                self.replanner.request()
                self.stuck.reset()
            return step.v, step.w, False
        plan = self.replanner.update(t_s, grid, pose[:2], target_xy)
        if plan is None:
            return 0.0, 0.0, True
        v, w, done = self.follower.command(
            pose, plan.waypoints, tick_s, clear=clear_of_walls(grid, pose, self.footprint, self.body),
            nearer_m=self.footprint.lookaheads_m, creep_mps=self.footprint.creep_mps)
        arrived = done and float(np.hypot(*(np.array(plan.goal_xy) - pose[:2]))) < arrive_m
        if self.stuck.update(t_s, pose, commanded=abs(v) > 0.01 or abs(w) > 0.01):
            self._count_recovery(np.asarray(pose[:2], dtype=float))
            self.recovery.start(t_s, turn_sign=1.0 if rng.random() < 0.5 else -1.0)
        return v, w, arrived

    def _count_recovery(self, xy: np.ndarray) -> None:
        """One more recovery starting at ``xy`` (m): it extends the run when the robot is still near where the
        run began; after ``max_in_place`` of them the robot is :attr:`wedged`."""
        prm = self.recovery.params
        if self.run_from is None or float(np.hypot(*(xy - self.run_from))) >= prm.escape_m:
            self.run_from, self.in_place = xy, 0
        self.in_place += 1
        if self.in_place >= prm.max_in_place and not self.wedged:
            self.wedged = (f"wedged at ({xy[0]:.1f}, {xy[1]:.1f}) m: {self.in_place} stuck recoveries in a row "
                           f"left the robot within {prm.escape_m:g} m of where the first began")


class Driven:
    """A policy that drives with a :class:`DriveStack`: it stops when it gives up, or when the robot is wedged."""

    drive: DriveStack
    stopped = ""  # why the policy itself stopped (empty: it has not)

    @property
    def gave_up(self) -> str:
        """Why the policy stopped (non-empty ends the trial): its own reason, or :attr:`DriveStack.wedged`."""
        return self.stopped or self.drive.wedged

    @gave_up.setter
    def gave_up(self, why: str) -> None:
        self.stopped = why


class AbstractMapPolicy(Driven):
    """What every policy that keeps an abstract map shares: the model, its drive stack, cues and settle times."""

    target: object | None  # the current target, forgotten when the model changes

    def __init__(self, world: World, goal: str, start: Pose, params: PolicyParams) -> None:
        self.params = params
        self.nav = Navigator.start(world, goal, start, params=params.navigator)
        self.drive = DriveStack(params)
        self.target = None
        self.target_at = -float("inf")
        self.bumps = 0  # exploration bumps in all
        self.start = np.asarray(start, dtype=float)
        self.evidence: np.ndarray | None = None  # depth x route likelihood, per grid cell
        self.factors: dict[str, np.ndarray] = {}  # the evidence's factors by name (EVIDENCE_FACTORS), per grid cell
        self.evidence_key: tuple = ()  # the arrows and unnamed signs the evidence was worked out from
        self.evidence_at = -float("inf")
        self.evidence_count = 0  # refreshes of the evidence so far (what was worked out from it knows its age)
        self.searches = PathSearches()  # the evidence's path searches, run again only on a changed map
        self.now = 0.0  # s, simulated time of the latest command

    @property
    def cues(self) -> list[CueEvent]:
        return self.nav.cues

    def observe(self, sightings: Iterable[Sighting], *, t_s: float, distance_m: float,
                grid: OccupancyGrid, spotted: Sequence[Spot] = ()) -> None:
        if self.nav.observe(sightings, t_s=t_s, distance_m=distance_m, explored_centre=grid.explored_centre):
            self.forget_target()

    def forget_target(self) -> None:
        """The model changed: the target chosen from it is chosen again."""
        self.target = None

    def settles(self) -> list[SettleReport]:
        return self.nav.settles

    def fed_back_belief(self, grid: OccupancyGrid, swept: np.ndarray, below: float) -> Belief:
        """The goal belief over ``grid`` with ``swept`` (bool per cell) counted as looked at, negative
        information fed back into the abstract map: with less than ``below`` of the goal's prior left unswept
        (``Belief.remaining``) the label is not where the model imagines it, so the model grows by one
        exploration step, settles again and the belief is made from it (the paper's bump, triggered by the
        space looked at instead of by arriving at the imagined goal; none once the bumps in a row run out)."""
        belief = goal_belief(grid, swept, self.goal_prior(), self.params.belief, self._evidence(grid))
        if belief.remaining < below and self.nav.arrived_without_goal(grid.explored_centre()):
            self.bumps += 1
            belief = goal_belief(grid, swept, self.goal_prior(), self.params.belief, self._evidence(grid))
        return belief

    def goal_prior(self, belief: BeliefParams | None = None) -> GoalPrior:
        """The goal's imagined position (m; off the map too: a prior's near edge then lies on it), the spread
        (m) the model earns there (:func:`sim.navigation.belief.goal_sigma`, with ``belief`` or the policy's own
        parameters) and the labels read of its siblings, with the way each faces and how much that counts in
        this building (:meth:`family`)."""
        goal = self.nav.model.goal_estimate()
        anchors = np.array([f.xy for f in self.nav.model.fixed.values()])
        return GoalPrior(goal, goal_sigma(goal, anchors, belief or self.params.belief, self.nav.misses_m,
                                          self.placed_by()), *self.family())

    def placed_by(self) -> str:
        """How the cues read so far name the goal, the surest way (:func:`abstract_map.clauses.named_by`)."""
        model = self.nav.model
        return named_by((c for clauses in model.cue_clauses.values() for c in clauses), self.nav.goal,
                        model.canonical)

    def family_labels(self) -> np.ndarray:
        """(K, 2) m: where the labels read of the goal's siblings hang (places with the goal's parent area,
        the goal excluded); none when the goal has no parent or its parent is the hierarchy's root (the
        whole building is no area)."""
        return self.family()[0]

    def labels_read(self) -> list[tuple[FixedPoint, str]]:
        """Each label read: where it hangs and which way it faces (its fixed point), and the place it names
        (canonical spelling)."""
        model = self.nav.model
        return [(model.fixed[anchor], model.canonical(c.toponym)) for anchor, clauses in model.cue_clauses.items()
                for c in clauses if isinstance(c, Locational) and c.kind == "label"]

    def family(self) -> tuple[np.ndarray, np.ndarray, float]:
        """:meth:`family_labels`, the way each of those labels faces ((K,) rad) and how much the way they face
        counts (:func:`sim.navigation.belief.across_ratio` of every label read of a place in an area)."""
        siblings, parents, read = self._siblings(), self.nav.model.hierarchy.parent, self.labels_read()
        found = [point for point, name in read if name in siblings]
        in_areas = [(point, parents[name]) for point, name in read if parents.get(name) in parents]
        across = across_ratio(np.array([p.xy for p, _ in in_areas], dtype=float),
                              np.array([p.theta for p, _ in in_areas], dtype=float),
                              [a for _, a in in_areas], self.params.belief) if found else 1.0
        return (np.array([f.xy for f in found], dtype=float).reshape(-1, 2),
                np.array([f.theta for f in found], dtype=float), across)

    def _siblings(self) -> set[str]:
        """The places sharing the goal's parent area, the goal excluded; none when the goal has no parent or its
        parent is the hierarchy's root (the whole building is no area)."""
        parents = self.nav.model.hierarchy.parent
        area = parents.get(self.nav.goal)
        if area is None or area not in parents:
            return set()
        return {name for name, parent in parents.items() if parent == area and name != self.nav.goal}

    def _areas(self) -> set[str]:
        """The places that hold the goal, up the hierarchy."""
        model, areas, place = self.nav.model, set(), self.nav.goal
        while place in model.hierarchy.parent and place not in areas:
            place = model.hierarchy.parent[place]
            areas.add(place)
        return areas

    def arrows(self) -> list[Arrow]:
        """One arrow per sign and direction read that names the goal, or (less surely) an area holding it or a
        sibling: a place of the goal's area, whose route leads into that area as an area's own arrow does (to one
        of its rooms). A sibling's arrow counts only on a sign that does not name the goal itself (in an arrow or
        a phrase): there the sign has said where the goal is, and its siblings' ways are their own. An arrow
        naming several of them is one statement of a way, as sure as its surest name."""
        model, rp, goal = self.nav.model, self.params.routes, self.nav.goal
        areas, siblings = self._areas(), self._siblings()
        naming_goal = {anchor for anchor, clauses in model.cue_clauses.items() if goal in self._names(clauses)}
        surest: dict[tuple[str, float], float] = {}
        for clause in model.clauses():
            if not isinstance(clause, Locational) or clause.kind != "arrow" or clause.anchor not in model.fixed:
                continue
            name = model.canonical(clause.toponym)
            if name == goal or name in areas or (name in siblings and clause.anchor not in naming_goal):
                key = (clause.anchor, clause.direction)
                surest[key] = min(rp.wrong_prob if name == goal else rp.area_wrong_prob, surest.get(key, 1.0))
        signs = model.fixed
        return [Arrow((signs[a].x, signs[a].y), signs[a].theta, direction, wrong)
                for (a, direction), wrong in surest.items()]

    def _names(self, clauses: Iterable[Clause]) -> set[str]:
        """Every place ``clauses`` name (canonical spelling), in arrows, labels and phrases."""
        model = self.nav.model
        return {model.canonical(name) for c in clauses for name in clause_names(c) if not is_anchor(name)}

    def unnamed(self) -> list[tuple[float, float]]:
        """Where the reader of each sign read stands (m, ``RouteParams.stand_m`` in front of it) that has an
        arrow and names neither the goal nor an area holding it, in an arrow or a phrase (a sibling named does
        not count: signs on a place's route name it or its area, ``RouteParams.named_prob``)."""
        model, stand = self.nav.model, self.params.routes.stand_m
        wanted = self._areas() | {self.nav.goal}
        out = []
        for anchor, clauses in model.cue_clauses.items():
            sign = model.fixed.get(anchor)
            if sign is None or not any(isinstance(c, Locational) and c.kind == "arrow" for c in clauses):
                continue
            if not self._names(clauses) & wanted:
                out.append((sign.x + stand * math.cos(sign.theta), sign.y + stand * math.sin(sign.theta)))
        return out

    def other_doors(self) -> list[tuple[tuple[float, float], float]]:
        """Each label read (position m, facing rad) of a place whose parent is an area that neither is nor holds
        the goal's: the room behind its door is another area's (:mod:`sim.navigation.rooms`)."""
        parents, own = self.nav.model.hierarchy.parent, self._areas()
        return [((tag.x, tag.y), tag.theta) for tag, name in self.labels_read()
                if name != self.nav.goal and parents.get(name) in parents and parents[name] not in own]

    def evidence_factors(self, grid: OccupancyGrid, routes: RouteParams, searches: PathSearches,
                         names: Iterable[str] = EVIDENCE_FACTORS) -> dict[str, np.ndarray]:
        """The evidence's factors ``names`` (of :data:`EVIDENCE_FACTORS`, in that order), per grid cell, worked out
        with the route parameters ``routes``: door depth from the start, the likelihood of the arrows read, that
        of the signs read that name neither the goal nor an area holding it, and that of the rooms behind doors
        whose labels name another area's place (:mod:`sim.navigation.rooms`). A factor with nothing to say (no
        such arrow, sign or door read) is left out; door depth is always there."""
        makers = {"doors": lambda: door_depth_weight(grid, self.start[:2], routes, searches),
                  "arrows": lambda: route_likelihood(grid, self.arrows(), routes, searches, self.bearing_share()),
                  "unnamed signs": lambda: passed_likelihood(grid, self.unnamed(), self.start[:2], routes, searches),
                  "other rooms": lambda: other_rooms_likelihood(grid, self.other_doors(), self.params.rooms)}
        found = {name: makers[name]() for name in names}
        return {name: factor for name, factor in found.items() if factor is not None}

    def bearing_share(self) -> float:
        """The chance this building's arrows point at their places (fingerposts) rather than the way: 0, the
        route reading, unless a policy tests it (:class:`GuidedPolicy`)."""
        return 0.0

    @property
    def depth(self) -> np.ndarray:
        """The door-depth weight per grid cell (the evidence's ``doors`` factor); 1 before the first evidence."""
        return self.factors.get("doors", np.ones(1))

    def _evidence(self, grid: OccupancyGrid) -> np.ndarray:
        """Door depth x route likelihood of the arrows read x that of the signs not naming the goal x that of the
        rooms behind doors labelled with another area's place, per grid cell; refreshed when a new sign or such a
        label is read or every ``evidence_every_s`` (walls and doors are mapped slowly)."""
        arrows, unnamed = self.arrows(), self.unnamed()
        key = (*arrows, *unnamed, len(self.other_doors()), self.bearing_share())
        if self.evidence is None or key != self.evidence_key or self.now - self.evidence_at >= \
                self.params.routes.evidence_every_s:
            self.factors = self.evidence_factors(grid, self.params.routes, self.searches)
            self.evidence = functools.reduce(np.multiply, self.factors.values())
            self.evidence_key, self.evidence_at = key, self.now
            self.evidence_count += 1
        return self.evidence


class PaperPolicy(AbstractMapPolicy):
    """The paper's robot: to the goal's imagined position, growing the model when it is not there."""

    target: Target | None

    def command(self, t_s: float, pose: Pose, grid: OccupancyGrid, tick_s: float,
                rng: np.random.Generator) -> tuple[float, float]:
        params = self.params
        # A stand-in target is kept until the model changes; the imagined goal is re-checked as the map grows.
        if self.target is None or (not self.target.local and t_s - self.target_at >= params.target_recheck_s):
            detours = self.nav.bumps_in_a_row >= params.targeting.local_bumps
            robot_xy = np.array(pose[:2])
            self.target = choose_target(grid, robot_xy, self.nav.target(robot_xy), params.planner,
                                        params.targeting, allow_detours=detours)
            self.target_at = t_s
        v, w, arrived = self.drive.drive(t_s, pose, grid, self.target.xy, tick_s, self.nav.params.arrive_m, rng)
        if arrived:
            if not self.nav.arrived_without_goal(grid.explored_centre()):
                self.gave_up = "exploration exhausted: the goal was not found where imagined"
                return 0.0, 0.0
            self.bumps += 1
            self.target = None
            self.drive.replanner.request()
        return v, w

    def picture(self) -> tuple[dict[str, tuple[float, float]], tuple[float, float], np.ndarray | None]:
        shown = self.nav.target() if self.target is None else self.target.xy
        plan = self.drive.plan
        return dict(imagined_positions(self.nav.model)), tuple(shown), None if plan is None else plan.waypoints


NO_FRONTIER = "no frontier left: explored all it could reach without reading the goal's label"


class FrontierSearch:
    """The loop every frontier search shares: look, keep the target while it is still on a frontier, choose
    afresh when it is reached or gone (and every ``rechoose_s``), drive to it.

    Space counts as explored once looked at from within reading range
    (:func:`sim.navigation.frontier.look`), not merely swept by the 8 m laser. A
    reached or unreachable target is never chosen again. :attr:`exhausted`
    turns true when no frontier is left.
    """

    def __init__(self, params: PolicyParams, drive: DriveStack, frontier: FrontierParams,
                 rechoose_s: float = math.inf) -> None:
        self.params, self.drive, self.frontier, self.rechoose_s = params, drive, frontier, rechoose_s
        self.target: np.ndarray | None = None
        self.chosen_at = self.checked_at = -float("inf")
        self.visited: list[np.ndarray] = []
        self.arrived_at: np.ndarray | None = None  # the target latest reached, until the caller takes it
        self.looked = LookedAt()
        self.unlooked: np.ndarray | None = None  # bool, the grid's shape: space to count as not yet looked at
        # whatever the looks say (the reading zones of plates seen but unread); None: none
        self.exhausted = False

    def command(self, t_s: float, pose: Pose, grid: OccupancyGrid, tick_s: float, rng: np.random.Generator,
                value: Callable[[np.ndarray], np.ndarray | None] = lambda covered: None,
                offset_m: float = 0.0, floor: float = 1e-6) -> tuple[float, float]:
        """The wheel command (m/s, rad/s) towards the frontier of least path length, or with ``value(covered)``
        (per grid cell, given the cells looked at, :attr:`unlooked` taken out; None: path alone) of least
        ``(path + offset_m) / value`` (a value below ``floor`` times the best counting as that)."""
        radius = self.params.planner.robot_radius_m
        covered = self.looked.update(grid, np.array(pose[:2]), self.frontier)
        if self.unlooked is not None and self.unlooked.shape == covered.shape:
            covered = covered & ~self.unlooked
        if self.target is not None and t_s - self.checked_at >= self.frontier.recheck_s:
            self.checked_at = t_s
            if not still_frontier(grid, self.target, radius, self.frontier, covered):
                self.target = None
        if self.target is None or t_s - self.chosen_at >= self.rechoose_s:
            self.target = nearest_frontier(grid, np.array(pose[:2]), radius, self.frontier, self.visited, covered,
                                           value=value(covered), offset_m=offset_m, floor=floor)
            self.chosen_at = self.checked_at = t_s
            self.drive.replanner.request()
            if self.target is None:
                self.exhausted = True
                return 0.0, 0.0
        v, w, arrived = self.drive.drive(t_s, pose, grid, self.target, tick_s, self.params.navigator.arrive_m, rng)
        if arrived:
            self.visited.append(self.target)
            self.target = None
            self.arrived_at = self.visited[-1]
        return v, w

    def shown(self) -> tuple[float, float]:
        """The target (m) for drawing; NaN when there is none."""
        return (math.nan, math.nan) if self.target is None else (float(self.target[0]), float(self.target[1]))


class SignBlind(Driven):
    """A driven policy that reads no sign: nothing to take in, no model to settle."""

    def __init__(self, params: PolicyParams) -> None:
        self.params = params
        self.drive = DriveStack(params)
        self.cues: list[CueEvent] = []  # reads no sign

    def observe(self, sightings: Iterable[Sighting], *, t_s: float, distance_m: float,
                grid: OccupancyGrid, spotted: Sequence[Spot] = ()) -> None:
        """Signs are not read: nothing to take in."""

    def settles(self) -> list[SettleReport]:
        return []


class FrontierPolicy(SignBlind):
    """Explore without reading signs: the nearest reachable frontier, until the goal's label is read.

    The trial judges success from the goal's label, so this policy ignores every
    sighting (:class:`FrontierSearch` by path length alone).
    """

    goal_blind = True  # its path never depends on the goal, so one run can stand for every goal of a world

    def __init__(self, world: World, goal: str, start: Pose, params: PolicyParams,
                 frontier: FrontierParams | None = None) -> None:
        super().__init__(params)
        self.search = FrontierSearch(params, self.drive, frontier or FrontierParams())

    def command(self, t_s: float, pose: Pose, grid: OccupancyGrid, tick_s: float,
                rng: np.random.Generator) -> tuple[float, float]:
        v, w = self.search.command(t_s, pose, grid, tick_s, rng)
        if self.search.exhausted:
            self.gave_up = NO_FRONTIER
        return v, w

    def picture(self) -> tuple[dict[str, tuple[float, float]], tuple[float, float], np.ndarray | None]:
        plan = self.drive.plan
        return {}, self.search.shown(), None if plan is None else plan.waypoints


class ViewpointPolicy(AbstractMapPolicy):
    """Negative information: to where the goal's label may still be read, growing the model when it is used up."""

    def __init__(self, world: World, goal: str, start: Pose, params: PolicyParams) -> None:
        super().__init__(world, goal, start, params)
        self.swept: SweptSpace | None = None
        self.belief: Belief | None = None
        self.views: Viewpoints | None = None
        self.target: np.ndarray | None = None
        self.swept_at = -float("inf")
        self.visited: list[np.ndarray] = []

    def command(self, t_s: float, pose: Pose, grid: OccupancyGrid, tick_s: float,
                rng: np.random.Generator) -> tuple[float, float]:
        vp = self.params.viewpoints
        self.now = t_s
        if self.swept is None:
            self.swept = SweptSpace(grid, self.params.belief)
        if t_s - self.swept_at >= vp.sweep_every_s:
            self.swept.sweep(grid, pose[:2])
            self.swept_at = t_s
        if self.target is None or t_s - self.target_at >= vp.retarget_s:
            self._retarget(t_s, np.array(pose[:2]), grid)
            if self.gave_up:
                return 0.0, 0.0
        assert self.target is not None
        v, w, arrived = self.drive.drive(t_s, pose, grid, self.target, tick_s, self.nav.params.arrive_m, rng)
        if arrived:
            self.visited.append(self.target)
            self.target = None
        return v, w

    def _retarget(self, t_s: float, robot_xy: np.ndarray, grid: OccupancyGrid) -> None:
        """Choose the viewpoint reading the most belief per metre; grow the model while the belief is used up."""
        vp, bp = self.params.viewpoints, self.params.belief
        assert self.swept is not None
        # One growth step at most per re-valuing, so the model moves out gradually.
        self.belief = self.fed_back_belief(grid, self.swept.swept, vp.exhausted_remaining)
        cues = cue_mass(grid, self.swept.swept, robot_xy, vp.cue_radius_m, bp) * self.depth
        mass = self.belief.mass + vp.cue_weight * cues / max(float(cues.sum()), 1e-12)
        travel = travel_costs(grid, robot_xy, self.params.planner, vp.escape_cost, pool=vp.travel_pool)
        self.views = views = score_viewpoints(grid, travel, mass, vp, bp, self.visited)
        self.target_at = t_s
        best = views.best()
        if best is None:
            if self.target is None:
                self.target = np.asarray(self.nav.target(robot_xy), dtype=float)
            return
        if self.target is not None:
            here = np.hypot(*(views.xy - self.target).T)
            current = int(np.argmin(here))
            if here[current] < vp.block_m and views.score[current] >= vp.keep_ratio * views.score[best]:
                return
        self.target = views.xy[best].copy()
        self.drive.replanner.request()

    def picture(self) -> tuple[dict[str, tuple[float, float]], tuple[float, float], np.ndarray | None]:
        shown = self.nav.target() if self.target is None else self.target
        plan = self.drive.plan
        return dict(imagined_positions(self.nav.model)), tuple(shown), None if plan is None else plan.waypoints

    def layers(self) -> dict[str, np.ndarray]:
        """For drawing, on the occupancy grid's cells: the goal belief (scaled to its peak) and the swept space."""
        out: dict[str, np.ndarray] = {}
        if self.belief is not None:
            peak = float(self.belief.mass.max())
            out["belief"] = self.belief.mass / peak if peak > 0 else self.belief.mass
        if self.swept is not None:
            out["swept"] = self.swept.swept
        return out


class GuidedPolicy(AbstractMapPolicy):
    """Sign-guided frontier search: the frontier with the most goal belief behind it per metre of path.

    The belief over where the goal's label hangs is the viewpoint policy's
    (:func:`sim.navigation.belief.goal_belief`): the abstract map's imagined goal
    as a prior, as wide as the model's own misses in this building, mixed with
    the labels read of the goal's siblings (:meth:`family`) as the model
    is trusted less (each on its own side of the way its label faces, as far as
    the labels read in this building say that an area keeps to one side of a
    corridor: :func:`sim.navigation.belief.across_ratio`), times every arrow
    read that names the goal or an area holding it and the doorways between the start and each place
    (:mod:`sim.navigation.routes`), little in the rooms behind doors whose labels name another area's place
    (:mod:`sim.navigation.rooms`), on mapped walls more than in unseen space,
    and little where the robot has already looked. Each frontier is worth the
    belief whose route from the robot enters unlooked space through it, as far
    as a walk on past it gives the best rate of belief per metre
    (:func:`sim.navigation.gateways.frontier_values`), so a corridor's open end
    carries what lies within reach along it and a room's doorway only the room,
    and a plate seen stands for the wall around it. Walls seen from
    afar with no plate on them are ruled out, and the space in front of each
    plate seen but not yet read counts as unlooked, so the robot steps in front
    of it (:mod:`sim.navigation.spotted`), and it reads a door's plate before
    going through the door. While the belief is used up (less than
    ``GuideParams.exhausted_remaining`` of the prior left unswept) the abstract map
    grows a step at a time (:meth:`fed_back_belief`), so the prior moves on from
    where the label has been looked for. The search is complete: it ends when
    the goal's label is read or no frontier is left.

    How far the abstract map's point is followed, and how the arrows are read,
    is decided by the building's own signs (:mod:`sim.navigation.fingerposts`):
    with the chance ``c`` that its arrows point at their places (fingerposts, as
    the paper reads them), the prior is ``c`` of the model's and ``1 - c`` of
    ``even-prior``'s (a :class:`~sim.navigation.belief.MixedPrior`), and each
    arrow's likelihood ``c`` of a bearing's and ``1 - c`` of a route's first leg.
    """

    feeds_back = True  # grows the abstract map when the belief is used up (False: a prior that is not the model's)
    tests_posts = True  # weighs the model's point and the arrows' reading by the fingerpost test (False: neither)
    spots = True  # takes in the plates seen but unread (``observe(..., spotted=...)``); other policies ignore them

    def __init__(self, world: World, goal: str, start: Pose, params: PolicyParams) -> None:
        super().__init__(world, goal, start, params)
        frontier = replace(FrontierParams(), min_distance_m=params.guide.min_target_m)
        self.search = FrontierSearch(params, self.drive, frontier, params.guide.rechoose_s)
        self.belief: Belief | None = None  # the latest goal belief, for drawing
        self.belief_swept: np.ndarray | None = None  # bool per grid cell: counted as looked at in that belief
        self.tags = SpottedTags(params.spotted)
        sp = params.spotted
        self.seen_from_afar: SweptSpace | None = None  # walls seen in the spotting rule: no unseen plate there
        self.seen_params = replace(params.belief, read_range_m=sp.sweep_range_m, read_min_m=0.0,
                                   cone_half_angle_deg=sp.sweep_cone_deg)
        self.seen_at = -float("inf")
        self.zones_version = -1
        self.stop: Spot | None = None  # the unread plate the robot is stepping in front of before its door
        self.door_asked: tuple | None = None  # (plan, plates' version, target) of the latest door_stop check
        self.posts = PostTest(params.guide.posts)  # whether this building's arrows point at their places

    def forget_target(self) -> None:
        self.search.target = None

    def observe(self, sightings: Iterable[Sighting], *, t_s: float, distance_m: float,
                grid: OccupancyGrid, spotted: Sequence[Spot] = ()) -> None:
        sightings = list(sightings)
        super().observe(sightings, t_s=t_s, distance_m=distance_m, grid=grid)
        self.tags.update(sightings, spotted)

    def _values(self, grid: OccupancyGrid, covered: np.ndarray, robot_xy: np.ndarray) -> np.ndarray:
        """Per grid cell, the goal belief behind it (:func:`sim.navigation.gateways.frontier_values`), and in
        front of each plate seen but unread, the belief on that plate."""
        plates, read = self.tags.tag_cells(grid), self.tags.read_cells(grid)
        self.posts.judge(grid, self._signs_read())
        self.belief_swept = (self._looked_or_seen(covered) & ~plates) | read
        self.belief = self.fed_back_belief(grid, self.belief_swept,
                                           self.params.guide.exhausted_remaining if self.feeds_back else 0.0)
        values = frontier_values(grid, self.belief.mass, covered, robot_xy, self.params.guide, self.params.routes)
        return np.maximum(values, self.tags.zone_values(grid, self.belief.mass))

    def goal_prior(self, belief: BeliefParams | None = None) -> GoalPrior | MixedPrior:
        """The abstract map's prior (:meth:`AbstractMapPolicy.goal_prior`) as far as the fingerpost test
        (:mod:`sim.navigation.fingerposts`) says this building's arrows point at their places; the rest of the
        chance lies as ``even-prior``'s prior does, even over the map until the goal's siblings are read."""
        own = super().goal_prior(belief)
        chance = self.posts.chance if self.tests_posts else 1.0
        if chance >= 1.0:
            return own
        return MixedPrior(((chance, own), (1.0 - chance, super().goal_prior(self.even_params(belief)))))

    def bearing_share(self) -> float:
        return self.posts.chance if self.tests_posts else 0.0

    def even_params(self, belief: BeliefParams | None = None) -> BeliefParams:
        """``belief`` (or the policy's own) with every floor of the prior's spread at ``even_spread_m``."""
        spread = self.params.guide.even_spread_m
        return replace(belief or self.params.belief, sigma_min_m=spread, sigma_min_arrow_m=spread,
                       sigma_min_hierarchy_m=spread)

    def _signs_read(self) -> Iterable[tuple[str, tuple[float, float], float, list[float]]]:
        """Each sign read with an arrow: its anchor, position (m), facing (rad) and arrows' directions (rad)."""
        model = self.nav.model
        for anchor, clauses in model.cue_clauses.items():
            sign = model.fixed.get(anchor)
            directions = [c.direction for c in clauses if isinstance(c, Locational) and c.kind == "arrow"]
            if sign is not None and directions:
                yield anchor, (sign.x, sign.y), sign.theta, directions

    def command(self, t_s: float, pose: Pose, grid: OccupancyGrid, tick_s: float,
                rng: np.random.Generator) -> tuple[float, float]:
        self.now = t_s
        robot_xy = np.array(pose[:2])
        if self.seen_from_afar is None or self.seen_from_afar.swept.shape != grid.shape:
            self.seen_from_afar = SweptSpace(grid, self.seen_params)
        if t_s - self.seen_at >= self.params.spotted.sweep_every_s:
            self.seen_from_afar.sweep(grid, robot_xy)
            self.seen_at = t_s
        if self.zones_version != self.tags.version:
            self.search.unlooked = self.tags.zones(grid)
            self.zones_version = self.tags.version
        v, w = self.search.command(t_s, pose, grid, tick_s, rng, value=lambda covered: self._values(
            grid, covered, robot_xy), offset_m=self.params.guide.offset_m, floor=self.params.guide.floor)
        self._read_before_door()
        if self.search.arrived_at is not None:
            self.tags.give_up_at(grid, self.search.arrived_at)
            self.search.arrived_at = None
        if self.search.exhausted:
            self.gave_up = NO_FRONTIER
        return v, w

    def _read_before_door(self) -> None:
        """When the planned path enters a door beside a plate not yet read, stand in front of the plate first
        (:meth:`~sim.navigation.spotted.SpottedTags.door_stop`); once it is read (or given up) the search
        chooses afresh. The next tick drives to the new target."""
        if self.stop is not None and self.stop not in self.tags.unread:
            self.stop = None
            self.search.target = None
        plan = self.drive.plan
        if self.search.target is None or plan is None:
            return
        asked = (plan, self.tags.version, tuple(self.search.target))
        if self.door_asked is not None and asked[0] is self.door_asked[0] and asked[1:] == self.door_asked[1:]:
            return  # the same path, plates and target as at the latest check: the same answer (no stop)
        self.door_asked = asked
        found = self.tags.door_stop(plan.waypoints)
        if found is None or float(np.hypot(*(found[1] - self.search.target))) < 1e-6:
            return
        self.stop, self.search.target = found
        self.drive.replanner.request()

    def picture(self) -> tuple[dict[str, tuple[float, float]], tuple[float, float], np.ndarray | None]:
        plan = self.drive.plan
        return dict(imagined_positions(self.nav.model)), self.search.shown(), None if plan is None else plan.waypoints

    def layers(self) -> dict[str, np.ndarray]:
        """For drawing, on the occupancy grid's cells: the goal belief (scaled to its peak) and the space looked at."""
        out: dict[str, np.ndarray] = {}
        if self.belief is not None:
            peak = float(self.belief.mass.max())
            out["belief"] = self.belief.mass / peak if peak > 0 else self.belief.mass
        if self.search.looked.covered is not None:
            out["swept"] = self._looked_or_seen(self.search.looked.covered)
        return out

    def _looked_or_seen(self, covered: np.ndarray) -> np.ndarray:
        """``covered`` (the cells looked at) and the walls seen from afar with no plate on them."""
        seen = self.seen_from_afar
        return covered | seen.swept if seen is not None and seen.swept.shape == covered.shape else covered


def oracle_label(world: World, goal: str, start: Pose) -> Tag:
    """The goal's label the oracle reads first from ``start`` (the world's truth: only the informed references
    may ask it); from the world's own start when ``start`` lies within the robot's radius of a wall."""
    from sim.world.oracle import oracle_path

    try:
        return world.tags[oracle_path(world, goal, (start[0], start[1])).tag_id]
    except ValueError:
        return world.tags[oracle_path(world, goal).tag_id]


class EvenPriorPolicy(GuidedPolicy):
    """``guided`` without the abstract map's imagined goal: an ablation that says what the model's point is worth.

    The floor of the goal prior's spread, for every way the cues name the goal,
    is ``GuideParams.even_spread_m`` (1 km; the model's misses average it down
    only slowly), so the prior lies even over the map until labels of the
    goal's siblings are read, which then hold it
    (:func:`sim.navigation.belief.prior_components`: a model that says nothing
    hands its share to them). The arrows, the signs that do not name the goal,
    door depth, the plates seen and the space looked at weigh it as in
    ``guided``. On the generator's buildings it walks shorter than ``guided``
    (their arrows give a route's first leg, not a bearing, so the model's point
    is worth less than none); in the zoo, whose arrows point at their places,
    it walks about 2.4 times the oracle (``docs/method-notes.md``, "What the
    imagined goal is worth" and "What telling the two kinds of building apart
    would be worth on the test split").
    """

    tests_posts = False  # the ablation: no point, arrows read as ways

    def goal_prior(self, belief: BeliefParams | None = None) -> GoalPrior:
        return AbstractMapPolicy.goal_prior(self, self.even_params(belief))


class KnownGoalPolicy(GuidedPolicy):
    """``guided`` told where the goal's label hangs: an informed reference, not a navigator for unseen buildings.

    The goal's prior sits on the label the oracle reads first from the start (the
    world's truth, :func:`sim.world.oracle.oracle_path`) with spread
    ``GuideParams.known_spread_m``; everything else is the guided search's, over
    a building the robot still has to map. What it walks beyond the oracle is
    what not knowing the building costs this search; what ``guided`` walks
    beyond it is what not knowing where the goal is costs (``docs/method-notes.md``,
    "The ceiling of a known goal").
    """

    feeds_back = False  # its prior sits on the label, not on the abstract map: growing the model moves nothing
    tests_posts = False  # an informed reference: its arrows read as ``even-prior``'s and main's were

    def __init__(self, world: World, goal: str, start: Pose, params: PolicyParams) -> None:
        super().__init__(world, goal, start, params)
        tag = oracle_label(world, goal, start)
        self.label_xy = np.array([tag.x, tag.y], dtype=float)

    def goal_prior(self) -> GoalPrior:
        return GoalPrior(self.label_xy, self.params.guide.known_spread_m, *self.family())


class KnownPosePolicy(SignBlind):
    """Told where the goal's label hangs and which way it faces: to the space in front of it, the shortest way
    over the robot's own map (unseen space as open, re-planned as the map grows), then turning to face it.

    The informed reference for what a building not yet mapped costs: the oracle knows the walls, this
    knows only the goal (``docs/method-notes.md``, "A known goal driven to"). Reads no sign.
    """

    def __init__(self, world: World, goal: str, start: Pose, params: PolicyParams) -> None:
        super().__init__(params)
        tag = oracle_label(world, goal, start)
        self.label_xy = np.array([tag.x, tag.y], dtype=float)
        facing = np.array([math.cos(tag.theta), math.sin(tag.theta)])
        self.target = self.label_xy + params.guide.known_front_m * facing
        self.arrived = False

    def command(self, t_s: float, pose: Pose, grid: OccupancyGrid, tick_s: float,
                rng: np.random.Generator) -> tuple[float, float]:
        if not self.arrived:
            v, w, self.arrived = self.drive.drive(t_s, pose, grid, self.target, tick_s,
                                                  self.params.navigator.arrive_m, rng)
            if not self.arrived:
                return v, w
        # In front of the label: turn to face it (the trial ends when it is read).
        bearing = math.atan2(self.label_xy[1] - pose[1], self.label_xy[0] - pose[0])
        return 0.0, self.params.follower.turn_in_place(wrap_angle(bearing - pose[2]))

    def picture(self) -> tuple[dict[str, tuple[float, float]], tuple[float, float], np.ndarray | None]:
        plan = self.drive.plan
        return {}, (float(self.target[0]), float(self.target[1])), None if plan is None else plan.waypoints


NAVIGATORS: dict[str, type] = {
    "paper": PaperPolicy,
    "frontier": FrontierPolicy,
    "viewpoint": ViewpointPolicy,
    "guided": GuidedPolicy,
    "even-prior": EvenPriorPolicy,
    "known-goal": KnownGoalPolicy,
    "known-pose": KnownPosePolicy,
}
"""Every navigation policy by its ``--navigator`` name; each is built as ``cls(world, goal, start, params)``."""


def make_policy(name: str, world: World, goal: str, start: Pose, params: PolicyParams) -> Policy:
    """The navigation policy ``name``; a ValueError lists the known ones."""
    try:
        cls = NAVIGATORS[name]
    except KeyError:
        raise ValueError(f"unknown navigator {name!r}; known navigators: {sorted(NAVIGATORS)}") from None
    return cls(world, goal, start, params)
