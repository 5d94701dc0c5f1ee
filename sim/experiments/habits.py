"""How a walk moved: turning round, walking ground already walked, weaving, and doorways crossed.

SPL says how much longer than the oracle a walk was, and :mod:`sim.experiments.walk` where the extra metres
lay against the goal's label. The habits here say what the robot did with them, the failure modes issue 10
names, measured from a trial's true path and the world's floor plan (never from what the robot knew):

- *turnarounds*: the heading ``turn_window_m`` of walk on differs from the heading now by more than
  ``turn_deg`` (a spur walked into and back out of, a doorway stepped into and left), counted once per
  ``turn_window_m`` run;
- *revisited*: metres walked within ``revisit_m`` of ground walked at least ``revisit_gap_m`` of walk earlier
  (a place returned to);
- *weave*: over windows of ``weave_window_m`` that run nearly straight (chord at least ``straight_share`` of
  the window), the walk beyond the chord, as a share of the walk in those windows (zig-zag along a corridor);
- *doorways*: passages narrower than ``door_width_m`` the robot's centre entered (into a room, or out of
  one); *doorways again*, entries of a doorway already entered twice (a room entered again);
- *entered unread*: entries of a doorway from the side a plate beside it faces (a label within
  ``plate_reach_m``) while that plate was still unread (turning in before reading the door's label), when
  the walk's reads are known.

A doorway is free floor whose run along a row or a column of the plan is narrower than ``door_width_m``, where
the robot's centre fits (:func:`doorway_cells`). World frame, metres.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from sim.world.data import Floorplan, Tag, World
from sim.world.oracle import oracle_paths, pool_plan


@dataclass(frozen=True)
class HabitParams:
    """What the habits count."""

    step_m: float = 0.1  # m between resampled points: under the 0.2 m depth of a wall, so a walk through a
    # doorway leaves a point in it
    turn_window_m: float = 3.0  # m of walk over which a heading is read (longer than a swerve round a jamb)
    turn_deg: float = 135.0  # deg; headings this far apart across the window are a turn round, not a corner
    revisit_m: float = 1.0  # m; ground within this of a walked point was walked (half a corridor's width)
    revisit_gap_m: float = 10.0  # m of walk before a point counts as walked earlier (not the stretch just walked)
    weave_window_m: float = 4.0  # m; windows of the walk judged for weaving (about a corridor segment's door gap)
    straight_share: float = 0.8  # a window whose chord is at least this share of it runs nearly straight
    door_width_m: float = 1.3  # m; narrower passages are doorways (the generator's doors are 1 m, corridors
    # 1.8 m and wider, hall exits 2 m; the routes' own rule, sim.navigation.routes.RouteParams.door_width_m)
    rejoin_m: float = 1.0  # m of walk; leaving a doorway for less than this and coming back is one visit (the
    # robot swaying on the threshold, or turning in a doorway)
    plate_reach_m: float = 1.5  # m from a doorway within which a label is its plate (the generator hangs labels
    # 0.85 m from a door's centre, so 0.35 m beyond its jamb)
    approach_m: float = 1.0  # m of walk before an entry where the side the robot came from is judged
    robot_radius_m: float = 0.38  # m; narrows the robot's centre cannot stand in are no passage (the planner's)
    cell_m: float = 0.1  # m, the grid the floor plan is pooled to for doorways


@dataclass(frozen=True)
class Habits:
    """One walk's habits (:mod:`sim.experiments.habits`)."""

    walked_m: float  # m, the resampled path's length
    turnarounds: int
    revisited_m: float  # m
    weave_m: float  # m walked beyond the chord in nearly straight windows
    straight_m: float  # m walked in those windows
    doorways: int  # doorway entries
    doorways_again: int  # entries of a doorway already entered twice
    entered_unread: int | None = None  # entries from a plate's side with the plate unread (None: reads unknown)


def resample(path_xy: np.ndarray, step_m: float, times: np.ndarray | None = None) -> np.ndarray:
    """(N, 2) m points every ``step_m`` along ``path_xy`` (M, 2) m, its first point first; a path that never
    moves is its first point. With ``times`` (M,) s, the time at each point instead, (N,) s."""
    path = np.asarray(path_xy, dtype=float).reshape(-1, 2)
    if len(path) == 0:
        return np.zeros((0, 2)) if times is None else np.zeros(0)
    along = np.r_[0.0, np.cumsum(np.hypot(*np.diff(path, axis=0).T))]
    at = np.arange(0.0, along[-1] + 1e-9, step_m)
    if times is not None:
        return np.interp(at, along, np.asarray(times, dtype=float))
    return np.stack([np.interp(at, along, path[:, 0]), np.interp(at, along, path[:, 1])], axis=1)


def turnarounds(points: np.ndarray, params: HabitParams = HabitParams()) -> int:
    """How often the walk through ``points`` (every ``step_m``) turns round: the heading over the window ahead
    against the heading over the window behind, more than ``turn_deg`` apart, once per run."""
    k = max(1, round(params.turn_window_m / params.step_m))
    if len(points) < 2 * k + 1:
        return 0
    behind = points[k:-k] - points[:-2 * k]
    ahead = points[2 * k:] - points[k:-k]
    cos = np.einsum("ij,ij->i", behind, ahead) / np.maximum(
        np.linalg.norm(behind, axis=1) * np.linalg.norm(ahead, axis=1), 1e-9)
    turned = cos < np.cos(np.radians(params.turn_deg))
    return _runs(turned, gap=k)


def revisited_m(points: np.ndarray, params: HabitParams = HabitParams()) -> float:
    """Metres of the walk through ``points`` (every ``step_m``) within ``revisit_m`` of a point walked at least
    ``revisit_gap_m`` before."""
    if len(points) < 2:
        return 0.0
    gap = round(params.revisit_gap_m / params.step_m)
    tree = cKDTree(points)
    again = np.zeros(len(points), dtype=bool)
    for i, near in enumerate(tree.query_ball_point(points, params.revisit_m)):
        again[i] = bool(near) and min(near) <= i - gap
    return float(again[1:].sum() * params.step_m)


def weave(points: np.ndarray, params: HabitParams = HabitParams()) -> tuple[float, float]:
    """(metres beyond the chord, metres walked) over the non-overlapping windows of ``weave_window_m`` of the walk
    through ``points`` (every ``step_m``) that run nearly straight (chord at least ``straight_share`` of the
    window)."""
    k = max(1, round(params.weave_window_m / params.step_m))
    window = k * params.step_m
    beyond = walked = 0.0
    for start in range(0, len(points) - k, k):
        chord = float(np.hypot(*(points[start + k] - points[start])))
        if chord >= params.straight_share * window:
            beyond += window - chord
            walked += window
    return beyond, walked


def doorway_cells(plan: Floorplan, params: HabitParams = HabitParams()) -> tuple[Floorplan, np.ndarray]:
    """The floor plan pooled to ``cell_m`` and its doorways: an int label per cell (0: none, k: doorway k).
    A doorway cell is a free cell whose run of free cells along its row or its column is narrower than
    ``door_width_m`` (doors in walls that run along the plan's axes, as the generator's do; a diagonal run
    would take every room's corners) and where the robot's centre fits (at least 0.9 of ``robot_radius_m``
    from any obstacle)."""
    pooled = pool_plan(plan, params.cell_m)
    free = ~pooled.occupied
    width = np.minimum(_run_lengths(free), _run_lengths(free.T).T) * pooled.resolution
    clearance = ndimage.distance_transform_edt(free) * pooled.resolution
    narrow = free & (width < params.door_width_m) & (clearance >= 0.9 * params.robot_radius_m)
    labels, _ = ndimage.label(narrow, structure=np.ones((3, 3)))
    return pooled, labels


def doorway_entries(points: np.ndarray, plan: Floorplan, doorways: np.ndarray,
                    params: HabitParams = HabitParams()) -> list[tuple[int, int]]:
    """The doorways (labels of :func:`doorway_cells`) the walk through ``points`` (every ``step_m``) enters, in
    order, each with the index of its first point inside; an entry within ``rejoin_m`` of walk of leaving the
    same doorway continues that visit (the robot swaying on the threshold), and a point off the plan is in
    none."""
    if len(points) == 0:
        return []
    cells = plan.world_to_pixel(points)
    rows, cols = doorways.shape
    inside = (cells[:, 0] >= 0) & (cells[:, 0] < rows) & (cells[:, 1] >= 0) & (cells[:, 1] < cols)
    at = np.where(inside, doorways[np.clip(cells[:, 0], 0, rows - 1), np.clip(cells[:, 1], 0, cols - 1)], 0)
    rejoin = round(params.rejoin_m / params.step_m)
    entries: list[tuple[int, int]] = []
    last: dict[int, int] = {}  # doorway -> index of the last point in it
    for i in np.flatnonzero(at):
        door = int(at[i])
        if i - last.get(door, -rejoin - 2) > rejoin + 1:
            entries.append((int(i), door))
        last[door] = int(i)
    return entries


def doorway_plates(plan: Floorplan, doorways: np.ndarray, tags: Iterable[Tag],
                   params: HabitParams = HabitParams()) -> dict[int, list[Tag]]:
    """Per doorway (labels of :func:`doorway_cells`), the labels among ``tags`` that hang beside it: within
    ``plate_reach_m`` of one of its cells, each beside the nearest doorway only."""
    cells = np.argwhere(doorways > 0)
    if len(cells) == 0:
        return {}
    tree = cKDTree(plan.pixel_to_world(cells))
    out: dict[int, list[Tag]] = {}
    for tag in tags:
        if tag.kind != "label":
            continue
        distance, i = tree.query((tag.x, tag.y))
        if distance <= params.plate_reach_m:
            out.setdefault(int(doorways[tuple(cells[i])]), []).append(tag)
    return out


def entered_unread(points: np.ndarray, times: np.ndarray, entries: Sequence[tuple[int, int]],
                   plates: dict[int, list[Tag]], read_s: dict[int, float],
                   params: HabitParams = HabitParams()) -> int:
    """How many of ``entries`` (:func:`doorway_entries` of ``points``, walked at ``times`` s) came from the side
    a plate of the doorway faces (the point ``approach_m`` of walk before the entry in front of it) while that
    plate was unread (``read_s``: tag id -> time first read, s)."""
    back = round(params.approach_m / params.step_m)
    count = 0
    for i, door in entries:
        before = points[max(i - back, 0)]
        count += any(
            (before[0] - tag.x) * np.cos(tag.theta) + (before[1] - tag.y) * np.sin(tag.theta) > 0
            and read_s.get(tag.id, np.inf) > times[i]
            for tag in plates.get(door, ()))
    return count


def habits(path_xy: np.ndarray, plan: Floorplan, doorways: np.ndarray, params: HabitParams = HabitParams(), *,
           times: np.ndarray | None = None, plates: dict[int, list[Tag]] | None = None,
           read_s: dict[int, float] | None = None) -> Habits:
    """The :class:`Habits` of a walk along ``path_xy`` (M, 2) m over ``plan`` with its ``doorways``
    (:func:`doorway_cells`). With the walk's ``times`` (M,) s, the doorways' ``plates``
    (:func:`doorway_plates`) and when each tag was first read (``read_s``, tag id -> s), the entries made
    before reading the door's plate too."""
    points = resample(path_xy, params.step_m)
    entries = doorway_entries(points, plan, doorways, params)
    passes: dict[int, int] = {}
    again = 0
    for _, door in entries:
        again += passes.get(door, 0) >= 2
        passes[door] = passes.get(door, 0) + 1
    unread = None
    if times is not None and plates is not None and read_s is not None:
        unread = entered_unread(points, resample(path_xy, params.step_m, times), entries, plates, read_s, params)
    beyond, straight = weave(points, params)
    return Habits(walked_m=max(len(points) - 1, 0) * params.step_m, turnarounds=turnarounds(points, params),
                  revisited_m=revisited_m(points, params), weave_m=beyond, straight_m=straight,
                  doorways=len(entries), doorways_again=again, entered_unread=unread)


def totals(walks: Sequence[Habits]) -> dict[str, float]:
    """Over ``walks``: turnarounds per 100 m, the share of the walk revisited and woven (%), and doorways,
    doorways entered again and doorways entered before reading their plate per walk (the last over the walks
    whose reads are known); nan for none."""
    walked = sum(h.walked_m for h in walks)
    known = [h.entered_unread for h in walks if h.entered_unread is not None]
    straight = sum(h.straight_m for h in walks)
    n = len(walks)
    return {
        "turnarounds per 100 m": 100 * sum(h.turnarounds for h in walks) / walked if walked else float("nan"),
        "revisited %": 100 * sum(h.revisited_m for h in walks) / walked if walked else float("nan"),
        "weave %": 100 * sum(h.weave_m for h in walks) / straight if straight else float("nan"),
        "doorways per walk": sum(h.doorways for h in walks) / n if n else float("nan"),
        "doorways again per walk": sum(h.doorways_again for h in walks) / n if n else float("nan"),
        "entered unread per walk": float(np.mean(known)) if known else float("nan"),
    }


def record_habits(record: Mapping[str, Any], plan: Floorplan, doorways: np.ndarray,
                  plates: dict[int, list[Tag]], params: HabitParams = HabitParams()) -> Habits | None:
    """:func:`habits` of a trial record's walk (its ``trajectory``, rows t s, x m, y m, ...) with the reads of its
    ``cues`` (a record of no read, a navigator that reads no sign, leaves the doorways entered unread unknown);
    None for a record without a trajectory."""
    trajectory = np.asarray(record.get("trajectory") or [], dtype=float)
    if trajectory.ndim != 2 or trajectory.shape[1] < 3:
        return None
    read_s: dict[int, float] = {}
    for cue in record.get("cues") or []:
        read_s.setdefault(int(cue["tag_id"]), float(cue["t_s"]))
    return habits(trajectory[:, 1:3], plan, doorways, params, times=trajectory[:, 0], plates=plates,
                  read_s=read_s if read_s else None)


def study_habits(records: Iterable[Mapping[str, Any]], worlds: Mapping[str, World],
                 group: Callable[[Mapping[str, Any]], str] = lambda record: "all",
                 params: HabitParams = HabitParams()) -> tuple[dict[tuple[str, str], list[Habits]], int]:
    """The habits of ``records``' walks by (navigator, ``group`` of the record), and the oracle's own paths to
    the same goals under ``"oracle"`` (once per world, goal and group; one search of each world's floor for
    all its goals); and how many records carried no walk to measure (no trajectory, or a world not in
    ``worlds``)."""
    by_world: dict[str, list[Mapping[str, Any]]] = defaultdict(list)
    unmeasured = 0
    for record in records:
        if record.get("world") in worlds:
            by_world[record["world"]].append(record)
        else:
            unmeasured += 1
    rows: dict[tuple[str, str], list[Habits]] = defaultdict(list)
    for name, mine in by_world.items():
        world = worlds[name]
        plan, doorways = doorway_cells(world.floorplan, params)
        plates = doorway_plates(plan, doorways, world.tags.values(), params)
        walked: set[tuple[str, str]] = set()  # (goal, group) walked by some navigator
        for record in mine:
            walk = record_habits(record, plan, doorways, plates, params)
            if walk is None:
                unmeasured += 1
                continue
            rows[record.get("navigator", "paper"), group(record)].append(walk)
            walked.add((record["goal"], group(record)))
        paths = oracle_paths(world, sorted({goal for goal, _ in walked})) if walked else {}
        for goal, key in sorted(walked):
            rows["oracle", key].append(habits(paths[goal].path, plan, doorways, params))
    return dict(rows), unmeasured


HABIT_COLUMNS = ("turnarounds per 100 m", "revisited %", "weave %", "doorways per walk", "doorways again per walk",
                 "entered unread per walk")  # the keys of :func:`totals`, in a table's order


def habits_legend(params: HabitParams = HabitParams()) -> str:
    """One paragraph saying what :func:`habits_table`'s columns count, with ``params``' values."""
    return (f"Counted from each walk's true path and the floor plan, beside the oracle's paths to the same goals "
            f"(`sim/experiments/habits.py`): turning round (the heading {params.turn_window_m:g} m on more than "
            f"{params.turn_deg:g} degrees from the heading {params.turn_window_m:g} m before), the share of the walk "
            f"within {params.revisit_m:g} m of ground walked {params.revisit_gap_m:g} m or more before, the share "
            f"woven beyond the chord on nearly straight {params.weave_window_m:g} m stretches, and per walk the "
            f"doorways passed (under {params.door_width_m:g} m wide, into a room or out), passed a third time or "
            f"more (a room entered again) and entered from the side of the label beside them before it was read.")


def habits_table(rows: Mapping[tuple[str, str], Sequence[Habits]], group_name: str = "group") -> list[str]:
    """Markdown lines: one row per (navigator, group) of :func:`study_habits`, with the walks, the metres walked
    per walk and :func:`totals`."""
    lines = [f"| navigator | {group_name} | walks | walked (m) | " + " | ".join(HABIT_COLUMNS) + " |",
             "|" + " --- |" * (4 + len(HABIT_COLUMNS))]
    for (navigator, group), walks in sorted(rows.items()):
        values = totals(walks)
        walked = sum(h.walked_m for h in walks) / len(walks)
        cells = ["-" if np.isnan(values[k]) else f"{values[k]:.2f}" for k in HABIT_COLUMNS]
        lines.append(f"| {navigator} | {group} | {len(walks)} | {walked:.1f} | " + " | ".join(cells) + " |")
    return lines


def _runs(flags: np.ndarray, gap: int) -> int:
    """How many runs of true ``flags``, runs less than ``gap`` apart counting as one."""
    hits = np.flatnonzero(flags)
    if len(hits) == 0:
        return 0
    return 1 + int(np.sum(np.diff(hits) > gap))


def _run_lengths(free: np.ndarray) -> np.ndarray:
    """Per cell of ``free`` (bool, rows x cols), the length in cells of the run of free cells along its row that
    holds it (0 where not free)."""
    rows, cols = free.shape
    padded = np.zeros((rows, cols + 2), dtype=bool)
    padded[:, 1:-1] = free
    edges = np.diff(padded.astype(np.int8), axis=1)
    out = np.zeros((rows, cols))
    for r in range(rows):
        starts, ends = np.flatnonzero(edges[r] == 1), np.flatnonzero(edges[r] == -1)
        for a, b in zip(starts, ends):
            out[r, a:b] = b - a
    return out
