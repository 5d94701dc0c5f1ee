"""The navigator: the abstract map's side of the loop, free of any simulator.

It turns tag sightings into observations of the abstract map, settles the
model when a new cue arrives, says where the robot should drive (the goal's
imagined position, kept inside the map's bounds), bumps exploration when the
robot arrives there without having read the goal's label, and declares success
when the goal's own label is read. World frame, metres, radians.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

import numpy as np

from abstract_map.hierarchy import Hierarchy
from abstract_map.model import AbstractMap, SettleReport
from abstract_map.params import AbstractMapParams
from sim.perception.sighting import Sighting
from sim.world.data import Tag, World

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class NavigatorParams:
    """How the navigator uses the abstract map."""

    arrive_m: float = 0.6  # m from the (reachable) imagined goal that counts as having arrived there
    bounds_margin_m: float = 0.5  # m, the target is kept this far inside the map's bounds
    max_bumps: int = 12  # exploration bumps in a row before the trial gives up ("exploration exhausted")


@dataclass(frozen=True)
class CueEvent:
    """A tag read for the first time."""

    tag_id: int
    text: str
    t_s: float  # simulated time
    distance_m: float  # robot's distance travelled so far
    settled: bool
    settle_iterations: int
    settle_wall_s: float


@dataclass
class Navigator:
    """Drives the abstract map from sightings; tells the robot where to go."""

    world: World
    goal: str
    model: AbstractMap
    params: NavigatorParams = field(default_factory=NavigatorParams)
    cues: list[CueEvent] = field(default_factory=list)
    settles: list[SettleReport] = field(default_factory=list)
    bumps_in_a_row: int = 0
    succeeded: bool = False
    misses_m: list[float] = field(default_factory=list)  # per label read first, how far (m) it lay from where
    # the model imagined its place just before: the model's track record in this building

    @classmethod
    def start(cls, world: World, goal: str, start_pose: tuple[float, float, float], *,
              params: NavigatorParams | None = None, model_params: AbstractMapParams | None = None) -> Navigator:
        """Load the hierarchy, anchor the model at ``start_pose`` and settle it."""
        hierarchy = Hierarchy.from_xml(world.hierarchy_path)
        model = AbstractMap.from_hierarchy(hierarchy, start_pose, goal=goal, params=model_params)
        model.set_explored_centre(start_pose[:2])
        nav = cls(world, model.goal or goal, model, params or NavigatorParams())
        nav.settles.append(model.settle())
        return nav

    def target(self, robot_xy: np.ndarray | None = None) -> np.ndarray:
        """Where to drive (m): the goal's imagined position, brought inside the map's bounds.

        A goal imagined off the map is brought back along the line from the robot
        (when given) to where that line leaves the map, so the robot still heads
        its way; without a robot position each coordinate is clamped.
        """
        x_min, x_max, y_min, y_max = self.world.floorplan.extent
        m = self.params.bounds_margin_m
        low, high = np.array([x_min + m, y_min + m]), np.array([x_max - m, y_max - m])
        goal = self.model.goal_estimate()
        if robot_xy is not None and np.all((low <= robot_xy) & (robot_xy <= high)):
            return clip_segment(np.asarray(robot_xy, dtype=float), goal, low, high)
        return np.clip(goal, low, high)

    def _is_goal_label(self, tag: Tag) -> bool:
        return tag.kind == "label" and self.model.canonical(tag.text) == self.goal

    def observe(self, sightings: Iterable[Sighting], *, t_s: float, distance_m: float,
                explored_centre: Callable[[], tuple[float, float] | None]) -> bool:
        """Feed sightings to the model; settle if any tag was new. True if the model changed.

        ``explored_centre`` is asked (m, world) only when the model settles.
        """
        new: list[Tag] = []
        for s in sightings:
            tag = self.world.tags.get(s.tag_id)
            if tag is None or tag.kind == "empty":
                continue
            if tag.kind == "label":
                self._record_miss(tag.text, s.x, s.y)
            observation = self.model.observe_tag(tag.id, tag.text, (s.x, s.y, s.theta), kind=tag.kind)
            if observation.new:
                new.append(tag)
            if self._is_goal_label(tag):
                self.succeeded = True
        if not new:
            return False
        self.bumps_in_a_row = 0
        report = self.settle(explored_centre())
        for tag in new:
            self.cues.append(CueEvent(tag.id, tag.text, t_s, distance_m, report.settled, report.iterations,
                                      report.wall_s))
            log.info("t=%.1fs read tag %d %r", t_s, tag.id, tag.text)
        return True

    def _record_miss(self, text: str, x: float, y: float) -> None:
        """Note how far a label read at (``x``, ``y``) (m) lies from its place as imagined, if the model imagined
        that place and had not yet observed it."""
        place = self.model.canonical(text)
        if place in self.model.positions and not self.model.is_observed(place):
            imagined = self.model.positions[place]
            self.misses_m.append(float(np.hypot(imagined[0] - x, imagined[1] - y)))

    def settle(self, explored_centre: tuple[float, float] | None) -> SettleReport:
        if explored_centre is not None:
            self.model.set_explored_centre(explored_centre)
        report = self.model.settle()
        if not report.settled:  # counted per trial (TrialResult.unsettled), so a study's log is not flooded
            log.debug("abstract map not settled after %d steps", report.iterations)
        self.settles.append(report)
        return report

    def arrived_without_goal(self, explored_centre: tuple[float, float] | None) -> bool:
        """The robot reached the imagined goal and did not see it: grow the model. False when exhausted."""
        if self.bumps_in_a_row >= self.params.max_bumps:
            return False
        self.bumps_in_a_row += 1
        factor = self.model.bump_exploration()
        log.info("goal not where imagined: exploration factor %.3f", factor)
        self.settle(explored_centre)
        return True


def clip_segment(start: np.ndarray, end: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """The point where the segment from ``start`` (inside the box) to ``end`` leaves the box, or ``end``."""
    direction = end - start
    t = 1.0
    for axis in range(2):
        if direction[axis] > 0:
            t = min(t, (high[axis] - start[axis]) / direction[axis])
        elif direction[axis] < 0:
            t = min(t, (low[axis] - start[axis]) / direction[axis])
    return start + max(0.0, t) * direction
