"""The campus benchmark: a robot walks a generated campus, reading one cue at a time, settling after each.

A campus of about N places: a grid of buildings, each of three wings (straight
corridors along +x) with ten rooms, five either side. Hierarchy: campus >
buildings > wings > rooms. Every cue comes from the true geometry:

- at each building's entrance a sign with an arrow (the nearest of LEFT, RIGHT,
  UP, DOWN to the true direction) to each of its wings and to the next two
  buildings of the walk, and "<wing 2> is past <wing 1>";
- at each wing's entrance a sign, "$UP$" every room of the wing (they lie
  ahead, through the sign) and "<room 6> is past <room 2>";
- a label beside every third room's door, facing the corridor, 2.5 m in front
  of the room's centre.

The robot walks the buildings in order, reading each building's sign, then
each wing's sign and its labels. Reported: median and p95 settle per cue (CPU
and wall), how many settles converged (and the first 50 cues whose settle
stopped at a cap), peak memory (the process's maximum
resident set), and the imagined-position error of places a sign has named but
whose label has not been read, after every settle (to the nearest cm), against their truth and
against guessing each at the sign that first named it.

    python benchmarks/campus.py 500 [--cues N] [--seed S] [--max-steps N] [--max-seconds S] [--json]
"""

from __future__ import annotations

import argparse
import json
import math
import resource
import statistics
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

sys.path.append(str(Path(__file__).resolve().parent.parent))  # after PYTHONPATH: another checkout may be measured

ROOMS_PER_WING = 10  # five either side of the corridor
WINGS = 3
ROOM_STEP_M = 4.0  # along the corridor
ROOM_OFFSET_M = 4.5  # corridor centre line to room centre
DOOR_OFFSET_M = 2.0  # corridor centre line to a label on its wall
WING_STEP_M = 14.0  # between corridors of a building
BUILDING_STEP_M = 70.0  # grid spacing of buildings
LABEL_EVERY = 3  # every third room's label is read

ARROWS = {"LEFT": -math.pi / 2, "RIGHT": math.pi / 2, "UP": math.pi, "DOWN": 0.0}


@dataclass
class Campus:
    """A generated campus: its hierarchy, the true position of every place, and the walk's cues."""

    tree: dict
    truth: dict[str, np.ndarray]
    cues: list[tuple[int, str, tuple[float, float, float]]] = field(default_factory=list)  # tag, text, pose
    start: tuple[float, float, float] = (0.0, 0.0, 0.0)


def _arrow(sign: np.ndarray, facing: float, target: np.ndarray) -> str:
    """The arrow whose direction (from a sign facing ``facing``) is nearest the true direction."""
    true = math.atan2(*(target - sign)[::-1])
    return min(ARROWS, key=lambda a: abs(math.remainder(facing + ARROWS[a] - true, math.tau)))


def generate(n_places: int, seed: int = 0) -> Campus:
    """A campus of about ``n_places`` places; ``seed`` jitters buildings (a numpy Generator, no global state)."""
    rng = np.random.default_rng(seed)
    per_building = 1 + WINGS * (1 + ROOMS_PER_WING)
    n_buildings = max(1, round((n_places - 1) / per_building))
    cols = math.ceil(math.sqrt(n_buildings))
    truth: dict[str, np.ndarray] = {}
    tree: dict = {"Campus": {}}
    corridors: dict[str, tuple[np.ndarray, list[str]]] = {}  # wing -> (corridor start, rooms in order)
    origins = []
    for b in range(n_buildings):
        origin = np.array([(b % cols) * BUILDING_STEP_M, (b // cols) * BUILDING_STEP_M]) + rng.uniform(-5, 5, 2)
        origins.append(origin)
        building = f"B{b}"
        tree["Campus"][building] = {}
        for w in range(WINGS):
            wing = f"B{b} W{w}"
            start = origin + np.array([0.0, w * WING_STEP_M])
            rooms = []
            for r in range(ROOMS_PER_WING):
                side = 1 if r % 2 == 0 else -1
                name = f"B{b} W{w} R{r}"
                truth[name] = start + np.array([4.0 + (r // 2) * ROOM_STEP_M, side * ROOM_OFFSET_M])
                rooms.append(name)
            tree["Campus"][building][wing] = {room: {} for room in rooms}
            truth[wing] = np.mean([truth[r] for r in rooms], axis=0)
            corridors[wing] = (start, rooms)
        truth[building] = np.mean([truth[f"B{b} W{w}"] for w in range(WINGS)], axis=0)
    truth["Campus"] = np.mean([truth[f"B{b}"] for b in range(n_buildings)], axis=0)
    campus = Campus(tree, truth, start=(float(origins[0][0] - 20.0), float(origins[0][1] + WING_STEP_M), 0.0))
    for b in range(n_buildings):
        sign = origins[b] + np.array([-6.0, WING_STEP_M])  # west of the middle wing, facing west (the reader)
        facing = math.pi
        lines: dict[str, list[str]] = {}
        for target in [f"B{b} W{w}" for w in range(WINGS)] + [f"B{o}" for o in (b + 1, b + 2) if o < n_buildings]:
            lines.setdefault(_arrow(sign, facing, truth[target]), []).append(target)
        text = "\n".join(f"${arrow}$ {', '.join(names)}" for arrow, names in lines.items())
        text += f"\nB{b} W2 is past B{b} W1"
        campus.cues.append((len(campus.cues), text, (float(sign[0]), float(sign[1]), facing)))
        for w in range(WINGS):
            start, rooms = corridors[f"B{b} W{w}"]
            text = f"$UP$ {', '.join(rooms)}\n{rooms[6]} is past {rooms[2]}"
            campus.cues.append((len(campus.cues), text, (float(start[0] - 1.0), float(start[1]), math.pi)))
            for r, room in enumerate(rooms):
                if r % LABEL_EVERY:
                    continue
                side = 1 if r % 2 == 0 else -1
                tag = truth[room] + np.array([0.0, -side * (ROOM_OFFSET_M - DOOR_OFFSET_M)])
                facing_corridor = -side * math.pi / 2  # the label faces the corridor; its room lies behind it
                campus.cues.append((len(campus.cues), room, (float(tag[0]), float(tag[1]), facing_corridor)))
    return campus


class Histogram:
    """Distances (m) counted in 1 cm bins up to 10 km, so the median over every place after every settle
    takes a fixed amount of memory however long the walk (tens of millions of distances at 20,000 places)."""

    BIN_M = 0.01
    TOP_M = 10_000.0

    def __init__(self) -> None:
        self.bins = np.zeros(int(self.TOP_M / self.BIN_M) + 1, dtype=np.int64)

    def add(self, distances: np.ndarray) -> None:
        """Count ``distances`` (m); those beyond 10 km go in the last bin."""
        index = np.minimum(np.asarray(distances) / self.BIN_M, len(self.bins) - 1).astype(np.int64)
        self.bins += np.bincount(index, minlength=len(self.bins))

    @property
    def count(self) -> int:
        return int(self.bins.sum())

    def median(self) -> float:
        """The median distance (m) to the nearest cm, the middle of its bin; NaN if nothing was counted."""
        if not self.count:
            return math.nan
        middle = int(np.searchsorted(np.cumsum(self.bins), (self.count + 1) / 2))
        return (middle + 0.5) * self.BIN_M


def walk(campus: Campus, *, max_cues: int | None = None, max_seconds: float | None = None,
         max_steps: int | None = None) -> dict:
    """Feed the cues one at a time, settling after each (capped at ``max_steps`` steps and ``max_seconds``
    of wall time per settle when given); the figures of the benchmark."""
    from abstract_map.clauses import Locational
    from abstract_map.hierarchy import Hierarchy
    from abstract_map.model import AbstractMap

    model = AbstractMap.from_hierarchy(Hierarchy.from_nested(campus.tree), campus.start)
    visited = np.array(campus.start[:2])
    model.set_explored_centre(visited)
    caps_kw = {k: v for k, v in (("max_s", max_seconds), ("max_steps", max_steps)) if v is not None}
    # (older checkouts have no per-call caps: nothing is passed unless asked for)
    cpu0, wall0 = time.process_time(), time.perf_counter()
    model.settle(**caps_kw)
    first = (time.process_time() - cpu0, time.perf_counter() - wall0)
    cpu, wall, steps, moved, converged, caps = [], [], [], [], 0, {"steps": 0, "time": 0}
    capped_at: list[int] = []  # the cues (1 = the first) whose settle stopped at a cap
    named_at: dict[str, np.ndarray] = {}  # place -> the sign that first named it
    seen: set[str] = set()
    errors, guesses = Histogram(), Histogram()
    cues = campus.cues if max_cues is None else campus.cues[:max_cues]
    for i, (tag, text, pose) in enumerate(cues, start=1):
        observation = model.observe_tag(tag, text, pose)
        visited = visited + (np.array(pose[:2]) - visited) / (i + 1)  # mean of the start and every cue pose
        model.set_explored_centre(visited)
        cpu0, wall0 = time.process_time(), time.perf_counter()
        report = model.settle(**caps_kw)
        cpu.append(time.process_time() - cpu0)
        wall.append(time.perf_counter() - wall0)
        steps.append(report.iterations)
        moved.append(getattr(report, "moved", len(model.positions)))  # older checkouts move every place
        converged += report.settled
        cap = getattr(report, "stopped_by", "" if report.settled else "steps")
        if cap:
            caps[cap] += 1
            capped_at.append(i)
        for clause in observation.clauses:
            if isinstance(clause, Locational) and clause.kind == "label":
                seen.add(clause.toponym)
            else:
                for name in (getattr(clause, "toponym", None), getattr(clause, "figure", None),
                             *getattr(clause, "referents", ())):
                    if name in campus.truth:
                        named_at.setdefault(name, np.array(pose[:2]))
        if i % 100 == 0:
            print(f"campus {len(campus.truth)}: {i}/{len(cues)} cues, median settle so far "
                  f"{1000 * statistics.median(cpu):.0f} ms CPU, {converged}/{i} converged", file=sys.stderr, flush=True)
        unseen = [name for name in named_at if name not in seen]
        if unseen:
            truth = np.array([campus.truth[name] for name in unseen])
            imagined = np.array([model.positions[name] for name in unseen])
            errors.add(np.hypot(*(imagined - truth).T))
            guesses.add(np.hypot(*(np.array([named_at[name] for name in unseen]) - truth).T))
    return {
        "places": len(model.places()), "springs": len(model.springs()), "cues": len(cues),
        "of_cues": len(campus.cues), "first_settle_cpu_s": first[0], "first_settle_wall_s": first[1],
        "median_cpu_ms": 1000 * statistics.median(cpu), "p95_cpu_ms": 1000 * float(np.percentile(cpu, 95)),
        "median_wall_ms": 1000 * statistics.median(wall), "p95_wall_ms": 1000 * float(np.percentile(wall, 95)),
        "max_cpu_ms": 1000 * max(cpu, default=math.nan),
        "median_steps": statistics.median(steps), "max_steps": max(steps, default=0),
        "median_moved": statistics.median(moved),
        "converged": converged, "caps": caps, "capped_cues": capped_at[:50],
        "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "error_median_m": errors.median(), "guess_median_m": guesses.median(),
        "errors_counted": errors.count, "module": sys.modules["abstract_map"].__file__,
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("places", type=int)
    parser.add_argument("--cues", type=int, default=None, help="stop after this many cues (default: the whole walk)")
    parser.add_argument("--seed", type=int, default=0, help="campus jitter seed (development seeds 0-999)")
    parser.add_argument("--max-seconds", type=float, default=None, help="wall-time cap per settle")
    parser.add_argument("--max-steps", type=int, default=None,
                        help="step cap per settle (default: the model's DynamicsParams.max_iterations, 50,000)")
    parser.add_argument("--json", action="store_true", help="print one JSON line")
    args = parser.parse_args()
    if args.max_steps is not None or args.max_seconds is not None:  # older checkouts have no per-call caps
        from abstract_map.errors import AbstractMapError
        from abstract_map.model import settle_caps

        try:
            settle_caps(args.max_steps, args.max_seconds, names=("--max-steps", "--max-seconds"),
                        error=AbstractMapError)
        except AbstractMapError as error:
            parser.error(str(error))
    figures = walk(generate(args.places, args.seed), max_cues=args.cues, max_seconds=args.max_seconds,
                   max_steps=args.max_steps)
    print(json.dumps(figures) if args.json else "\n".join(f"{k}: {v}" for k, v in figures.items()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
