"""A trial recorded for the rerun viewer, on the simulated-time line ``sim`` (``rerun run.rrd`` opens it).

:class:`Recorder` is a trial observer (see :class:`~sim.experiments.trial.Trial`):
it logs what the trial did after every control tick. Entities, in the world
frame (metres, z up) unless said otherwise:

- ``world/floorplan``: the building's walls (static grid map); ``world/tags``: every tag, an arrow along its face
- ``world/robot``: the robot's true pose (a transform), with ``world/robot/body`` (a box) and
  ``world/robot/laser`` (the latest scan's hits, robot frame)
- ``world/path``: the path driven so far; ``world/occupancy``: the occupancy grid as it grows
- ``camera/view_K``: each rendered camera view (JPEG), with ``camera/view_K/tags`` outlining every detected tag
  (green: read; orange: found but outside the reading rules). Camera perception only: in geometric mode no
  images exist and none are logged.
- ``cues`` (text log) and ``world/cues``: each cue's text when first read, at its tag
- ``world/abstract_map/places``, ``.../goal``, ``.../fixed``, ``.../springs``: the imagined places and the springs
  after every settle (policies without an abstract map log their places only, no springs)
- ``world/plan`` and ``world/target``: the planned path and the current target; ``events``: the verdict

rerun is imported here only, so the ``viz`` extra stays optional. The file is
written under a temporary name and renamed when the recording closes.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from sim.experiments.trial import Trial, TrialResult

TIMELINE = "sim"  # the simulated-time line, seconds
VIZ_HINT = 'recording a trial needs rerun-sdk: pip install "abstract-map[viz]"'

SPRING_COLOURS = {"distance": (31, 119, 180, 90), "global_angle": (255, 127, 14, 180),
                  "relative_angle": (44, 160, 44, 180)}  # as abstract_map.drawing's SPRING_STYLE
FIXED_COLOURS = {"label": (0, 0, 0), "sign": (214, 39, 40), "start": (148, 103, 189)}
TAG_COLOURS = {"label": (90, 90, 90), "sign": (214, 39, 40), "empty": (190, 190, 190)}
READ, REJECTED = (0, 200, 0), (255, 140, 0)  # tag outlines in camera views
ROS_FREE, ROS_OCCUPIED, ROS_UNKNOWN = 0, 100, 255  # nav_msgs/OccupancyGrid values (-1 as uint8), rviz colours


class MissingExtraError(ImportError):
    """An optional dependency is not installed; the message names the extra to install."""


def rerun_module() -> Any:
    """The ``rerun`` module, or a :class:`MissingExtraError` naming the ``viz`` extra."""
    try:
        import rerun
    except ModuleNotFoundError as exc:
        raise MissingExtraError(VIZ_HINT) from exc
    return rerun


@dataclass(frozen=True)
class RecordingParams:
    """How often the heavier entities are logged (the rest is logged when it changes)."""

    path_every_s: float = 1.0  # s of simulated time between re-logging the whole path driven
    grid_every_s: float = 1.0  # s between occupancy grid images (each one is the full grid)
    plan_every_s: float = 0.5  # s between checks of the planned path and target (logged when changed)
    jpeg_quality: int = 75  # camera views are stored as JPEG of this quality (1-100)
    flush_s: float = 2.0  # s of wall time rows are batched into chunks before writing (rerun's default is 0.2 s:
    # our loop then writes ~6x as many chunks and a file ~2x as large)
    flush_bytes: int = 2_000_000  # bytes, a chunk is written at this size whatever the time
    places_z_m: float = 0.05  # m, height of the abstract map's layer above the floor
    grid_z_m: float = 0.02  # m, height of the occupancy grid above the floor plan


def _grid_map(rr: Any, values: np.ndarray, resolution: float, origin: tuple[float, float], z: float,
              opacity: float) -> Any:
    """A rerun grid map of ``values`` (rows, cols) uint8 in ROS occupancy values, row 0 on top as in our images."""
    rows, cols = values.shape
    data = np.ascontiguousarray(np.flipud(values))  # a grid map's first row is at its lower-left corner
    return rr.GridMap(data=data.tobytes(), format=rr.components.ImageFormat(
        width=cols, height=rows, color_model="L", channel_datatype="U8"), cell_size=resolution,
        translation=[origin[0], origin[1], z], colormap=rr.components.Colormap.RvizMap, opacity=opacity)


def _blueprint(rr: Any, views: int) -> Any:
    rrb = rr.blueprint
    side = [rrb.TextLogView(origin="/cues", name="cues"), rrb.TextLogView(origin="/events", name="events")]
    if views:
        side.insert(0, rrb.Grid(*[rrb.Spatial2DView(origin=f"/camera/view_{k}", name=f"view {k}")
                                  for k in range(views)]))
    return rrb.Blueprint(rrb.Horizontal(rrb.Spatial3DView(origin="/world", name="world"), rrb.Vertical(*side),
                                        column_shares=[3, 2]))


class Recorder:
    """Logs a trial to a rerun file as it runs: append it to ``trial.observers``, :meth:`close` at the end."""

    def __init__(self, trial: Trial, path: str | os.PathLike[str], params: RecordingParams | None = None) -> None:
        self.rr = rr = rerun_module()
        self.params = prm = params or RecordingParams()
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.tmp = self.path.with_name(self.path.name + ".tmp")
        sweeps = hasattr(trial.sensor, "last_sweep")  # camera perception; geometric mode renders no images
        self.n_views = n_views = trial.sensor.params.n_views if sweeps else 0  # type: ignore[attr-defined]
        self.sweep: object | None = None  # the sweep logged last
        self.rec = rr.RecordingStream("abstract-map", recording_id=f"{trial.world.name}-{trial.goal}-{trial.seed}",
                                      batcher_config=rr.ChunkBatcherConfig(flush_tick=prm.flush_s,
                                                                           flush_num_bytes=prm.flush_bytes))
        self.rec.save(self.tmp, default_blueprint=_blueprint(rr, n_views))
        rr.set_log_time_enabled(False, recording=self.rec)
        every = {name: max(1, round(s / trial.tick)) for name, s in
                 (("path", prm.path_every_s), ("grid", prm.grid_every_s), ("plan", prm.plan_every_s))}
        self.every = every
        self.poses: list[tuple[float, float, float, float]] = []  # (t s, x m, y m, theta rad) not yet sent
        self.scans: list[tuple[float, np.ndarray]] = []  # (t s, hits (N, 3) m, robot frame) not yet sent
        self.cues = 0
        self.settles = -1
        self.plan: np.ndarray | None = None
        self.target: tuple[float, float] | None = None
        self._static(trial)
        self(trial)

    def _static(self, trial: Trial) -> None:
        rr, rec, world = self.rr, self.rec, trial.world
        rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        plan = world.floorplan
        walls = np.where(plan.occupied, ROS_OCCUPIED, ROS_FREE).astype(np.uint8)
        rec.log("world/floorplan", _grid_map(rr, walls, plan.resolution, plan.origin, 0.0, 0.5), static=True)
        tags = list(world.tags.values())
        rec.log("world/tags", rr.Arrows3D(
            origins=[[t.x, t.y, world.tag_height] for t in tags],
            vectors=[[0.4 * math.cos(t.theta), 0.4 * math.sin(t.theta), 0.0] for t in tags],
            colors=[TAG_COLOURS.get(t.kind, (128, 128, 128)) for t in tags],
            labels=[str(t.id) for t in tags], show_labels=False), static=True)
        robot = trial.robot.params
        rec.log("world/robot/body", rr.Boxes3D(half_sizes=[[robot.length / 2, robot.width / 2, 0.675]],
                                               centers=[[0.0, 0.0, 0.675]], colors=[(31, 119, 180)]), static=True)
        rec.log("world/robot/laser", rr.Points3D.from_fields(radii=0.03, colors=[(230, 30, 30)]), static=True)

    def __call__(self, trial: Trial) -> None:
        """Log the trial's state after a control tick (or at its start)."""
        rr, rec, n = self.rr, self.rec, trial.n
        rec.set_time(TIMELINE, duration=trial.t)
        x, y, theta = trial.last
        self.poses.append((trial.t, x, y, theta))
        if n % trial.every["map"] == 0 and trial.scan is not None:
            hit = trial.scan < trial.params.laser.max_range_m - 1e-6
            r, a = trial.scan[hit], trial.angles[hit]
            z = np.full(r.shape, trial.params.laser.height_m)
            self.scans.append((trial.t, np.stack([r * np.cos(a), r * np.sin(a), z], axis=1)))
        if n % self.every["path"] == 0 or trial.done:
            self._send_motion()
            path = np.array([row[1:3] for row in trial.trajectory] + [(x, y)])
            rec.log("world/path", rr.LineStrips3D([np.hstack([path, np.full((len(path), 1), 0.03)])],
                                                  radii=0.04, colors=[(31, 119, 180)]))
        if n % self.every["grid"] == 0 or trial.done:
            grid = trial.grid
            values = np.full(grid.shape, ROS_UNKNOWN, dtype=np.uint8)
            values[grid.free_mask()] = ROS_FREE
            values[grid.occupied_mask()] = ROS_OCCUPIED
            rec.log("world/occupancy", _grid_map(rr, values, grid.resolution, grid.origin,
                                                 self.params.grid_z_m, 0.6))
        if n % trial.every["see"] == 0:
            self._camera(trial)
        self._cues(trial)
        self._model(trial)
        if n % self.every["plan"] == 0 or trial.done:
            self._plan(trial)

    def _send_motion(self) -> None:
        """The poses and scans gathered since the last call, as columns (one call, not one per tick)."""
        rr, rec = self.rr, self.rec
        if self.poses:
            t, x, y, theta = np.array(self.poses).T
            zeros = np.zeros_like(t)
            rec.send_columns("world/robot", indexes=[rr.TimeColumn(TIMELINE, duration=t)],
                             columns=rr.Transform3D.columns(
                                 translation=np.stack([x, y, zeros], axis=1),
                                 quaternion=np.stack([zeros, zeros, np.sin(theta / 2), np.cos(theta / 2)], axis=1)))
            self.poses = []
        if self.scans:
            times, hits = zip(*self.scans)
            columns = rr.Points3D.columns(positions=np.vstack(hits)).partition([len(h) for h in hits])
            rec.send_columns("world/robot/laser", indexes=[rr.TimeColumn(TIMELINE, duration=times)], columns=columns)
            self.scans = []

    def _camera(self, trial: Trial) -> None:
        sweep = getattr(trial.sensor, "last_sweep", None)
        if sweep is None or sweep is self.sweep:
            return
        self.sweep = sweep
        rr, rec = self.rr, self.rec
        for k in range(self.n_views):
            entity = f"camera/view_{k}"
            if k not in sweep.images:
                rec.log(entity, rr.Clear(recursive=True))  # not rendered this sweep: no tag could be in it
                continue
            rec.log(entity, rr.Image(sweep.images[k]).compress(jpeg_quality=self.params.jpeg_quality))
            found = [d for d in sweep.detections[k] if d.corners_px is not None]
            rec.log(f"{entity}/tags", rr.LineStrips2D(
                [np.vstack([d.corners_px, d.corners_px[:1]]) for d in found],
                colors=[READ if d.tag_id in sweep.read else REJECTED for d in found],
                labels=[str(d.tag_id) for d in found], radii=1.0))

    def _cues(self, trial: Trial) -> None:
        cues = trial.policy.cues
        if len(cues) == self.cues:
            return
        rr, rec, tags = self.rr, self.rec, trial.world.tags
        for cue in cues[self.cues:]:
            rec.log("cues", rr.TextLog(f"tag {cue.tag_id} ({tags[cue.tag_id].kind}) at {cue.distance_m:.1f} m: "
                                       f"{cue.text}"))
        self.cues = len(cues)
        read = [tags[c.tag_id] for c in cues]
        rec.log("world/cues", rr.Points3D([[t.x, t.y, trial.world.tag_height] for t in read], radii=0.12,
                                          colors=[TAG_COLOURS.get(t.kind, (128, 128, 128)) for t in read],
                                          labels=[t.text for t in read]))

    def _model(self, trial: Trial) -> None:
        """The imagined places (and springs, when the policy has an abstract map) after every settle."""
        nav = getattr(trial.policy, "nav", None)
        model = getattr(nav, "model", None)
        marker = len(nav.settles) if model is not None else self.cues  # type: ignore[union-attr]
        if marker == self.settles:
            return
        self.settles = marker
        rr, rec, z = self.rr, self.rec, self.params.places_z_m
        if model is None:
            places = trial.policy.picture()[0]
            self._places(places, None)
            return
        from abstract_map.clauses import is_anchor

        places = {name: (float(p[0]), float(p[1])) for name, p in model.positions.items() if not is_anchor(name)}
        self._places(places, model.goal)
        fixed = list(model.fixed.values())
        rec.log("world/abstract_map/fixed", rr.Points3D(
            [[f.x, f.y, z] for f in fixed], radii=0.12, colors=[FIXED_COLOURS.get(f.kind, (0, 0, 0)) for f in fixed]))
        xy = {**{name: f.xy for name, f in model.fixed.items()}, **model.positions}
        strips, colours = [], []
        for spring in model.springs():
            if all(end in xy for end in spring.ends):
                strips.append([[*xy[end], z] for end in spring.ends])
                colours.append(SPRING_COLOURS.get(spring.kind, (128, 128, 128, 128)))
        rec.log("world/abstract_map/springs", rr.LineStrips3D(strips, colors=colours, radii=0.02))

    def _places(self, places: dict[str, tuple[float, float]], goal: str | None) -> None:
        rr, rec, z = self.rr, self.rec, self.params.places_z_m
        names = [name for name in places if name != goal]
        rec.log("world/abstract_map/places", rr.Points3D([[*places[n], z] for n in names], radii=0.15,
                                                         colors=[(44, 160, 44)], labels=names))
        if goal is not None and goal in places:
            rec.log("world/abstract_map/goal", rr.Points3D([[*places[goal], z]], radii=0.35, colors=[(255, 200, 0)],
                                                           labels=[goal]))

    def _plan(self, trial: Trial) -> None:
        _, target, plan = trial.policy.picture()
        rr, rec = self.rr, self.rec
        target = (float(target[0]), float(target[1]))
        if target != self.target:
            self.target = target
            rec.log("world/target", rr.Points3D([[*target, 0.1]], radii=0.25, colors=[(220, 0, 0)]))
        same = (plan is None) == (self.plan is None) and (plan is None or np.array_equal(plan, self.plan))
        if not same:
            self.plan = None if plan is None else plan.copy()
            if plan is None:
                rec.log("world/plan", rr.Clear(recursive=False))
            else:
                rec.log("world/plan", rr.LineStrips3D([np.hstack([plan, np.full((len(plan), 1), 0.06)])],
                                                      radii=0.03, colors=[(255, 127, 14)]))

    def close(self, result: TrialResult | None = None) -> Path:
        """Log the verdict, finish the file and move it into place; returns its path."""
        self._send_motion()
        if result is not None:
            verdict = "FOUND" if result.success else f"FAILED ({result.reason})"
            self.rec.log("events", self.rr.TextLog(f"{result.goal}: {verdict} after {result.distance_m:.1f} m, "
                                                   f"{result.sim_s:.1f} s simulated"))
        self.rec.flush()
        self.rec.disconnect()
        os.replace(self.tmp, self.path)
        return self.path

    def abandon(self) -> None:
        """Stop recording and remove the unfinished file."""
        self.rec.disconnect()
        self.tmp.unlink(missing_ok=True)
