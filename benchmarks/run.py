"""Benchmarks of abstract-map, printed as tables.

Run from the repository root:

    python benchmarks/run.py                  # settle, scaling, trials, study, generate (10-15 minutes on 2 cores)
    python benchmarks/run.py settle scaling   # just some of: settle, scaling, trials, study, generate, generalise
    python benchmarks/run.py generalise       # the generalisation benchmark (within an hour on 2 cores)
    python benchmarks/run.py generalise --buildings 6 --camera-buildings 2   # a quick run

settle   median settle time per cue on the Lion replay (the authors' code: 1.5-5.6 s)
scaling  settle time as the model grows: synthetic hierarchies of about 50, 500, 5,000 places with cues
         (a few minutes: the 5,000-place model takes about 13 ms per integration step)
trials   wall time and real-time factor of the Lion trial, per perception mode
study    total wall time of a small study (1 trial per goal, geometric, 2 workers)
generate time to generate a building per style and size, and how many pass the world check
generalise  test buildings (seeds 1000-1029, medium, styles and signage levels cycling), 5 goals each,
         geometric perception, navigators paper, frontier and guided; then 10 of them (1000-1009) with the
         camera and the guided navigator; each trial capped at 600 s simulated. Success, SPL, ratio to oracle
         and wall time per navigator and signage level, and per style.
         A resumable study folder (--out, default runs/generalise); named only, never part of the default set.
recording  what a rerun recording (--log) costs: the Kingfisher trial with and without it, per perception mode
           (needs the viz extra)
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
AUTHORS_SETTLE_S = (1.5, 5.6)  # per settle on the Lion sequence, the authors' implementation, this machine


def table(title: str, header: list[str], rows: list[list[str]]) -> None:
    widths = [max(len(str(x)) for x in col) for col in zip(header, *rows)]
    print(f"\n{title}")
    print("| " + " | ".join(h.ljust(w) for h, w in zip(header, widths)) + " |")
    print("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    for row in rows:
        print("| " + " | ".join(str(x).ljust(w) for x, w in zip(row, widths)) + " |")


def bench_settle() -> None:
    from abstract_map.scenario import load_scenario, replay

    scenario = load_scenario(ROOT / "worlds" / "zoo" / "lion_replay.json")
    runs = [replay(scenario)[1] for _ in range(3)]
    per_cue = [statistics.median(run[i]["wall_s"] for run in runs) for i in range(1, len(runs[0]))]
    rows = [[run_cue["cue"], str(run_cue["iterations"]), f"{t * 1000:.1f}",
             "({:.1f}, {:.1f})".format(*run_cue["goal"])] for run_cue, t in zip(runs[0][1:], per_cue)]
    median = statistics.median(per_cue)
    rows.append(["median", "", f"{median * 1000:.1f}", ""])
    table("Settle time per cue, Lion replay (median of 3 runs)", ["cue", "steps", "ms", "Lion imagined at (m)"], rows)
    low, high = AUTHORS_SETTLE_S
    print(f"authors' implementation: {low}-{high} s per settle -> {low / median:.0f}x to {high / median:.0f}x faster")


Cue = tuple[int, str, tuple[float, float, float]]  # tag id, text, pose (x m, y m, theta rad)


def synthetic(n_places: int, rng: np.random.Generator) -> tuple[dict, list[Cue]]:
    """A campus of about ``n_places`` places (buildings of 10 rooms) and the cues a robot would read."""
    n_buildings = max(1, round(n_places / 11))
    tree = {"Campus": {f"B{b}": {f"B{b} R{r}": {} for r in range(10)} for b in range(n_buildings)}}
    cues = []
    size = 12.0 * math.sqrt(n_buildings)
    for b in range(n_buildings):
        bx, by = rng.uniform(-size, size, 2)
        rooms = [f"B{b} R{r}" for r in range(10)]
        cues.append((len(cues), f"$LEFT$ {rooms[0]}, {rooms[1]}\n$RIGHT$ {rooms[2]}\n{rooms[3]} is past {rooms[1]}",
                     (bx, by, rng.uniform(-math.pi, math.pi))))
        for r in rng.choice(10, 2, replace=False):
            pose = (bx + rng.normal(0, 3), by + rng.normal(0, 3), rng.uniform(-math.pi, math.pi))
            cues.append((len(cues), rooms[r], pose))
    return tree, cues


def bench_scaling(sizes: tuple[int, ...] = (50, 500, 5000)) -> None:
    from abstract_map.hierarchy import Hierarchy
    from abstract_map.model import AbstractMap
    from abstract_map.params import AbstractMapParams, DynamicsParams

    rows = []
    for n in sizes:
        rng = np.random.default_rng(n)
        tree, cues = synthetic(n, rng)
        params = AbstractMapParams(dynamics=DynamicsParams(max_iterations=2000))
        model = AbstractMap.from_hierarchy(Hierarchy.from_nested(tree), (0.0, 0.0, 0.0), params=params)
        model.set_explored_centre((0.0, 0.0))
        began = time.perf_counter()
        model.settle()
        first_s = time.perf_counter() - began
        times, steps, settled = [], [], 0
        batch = max(1, -(-len(cues) // 3))  # settle after every third of the cues
        for i in range(0, len(cues), batch):
            for tag, text, pose in cues[i:i + batch]:
                model.observe_tag(tag, text, pose)
            report = model.settle()
            times.append(report.wall_s)
            steps.append(report.iterations)
            settled += report.settled
        print(f"scaling: {n} places done", file=sys.stderr, flush=True)
        rows.append([str(len(model.places())), str(len(model.springs())), f"{first_s * 1000:.0f}",
                     f"{statistics.median(times) * 1000:.0f}", str(int(statistics.median(steps))),
                     f"{statistics.median(t / s for t, s in zip(times, steps)) * 1000:.2f}",
                     f"{settled}/{len(times)}"])
    table("Settle time as the model grows (synthetic campus, settled after each third of its cues, 2,000-step cap)",
          ["places", "springs", "hierarchy settle (ms)", "median settle with cues (ms)", "median steps",
           "ms per step", "settled"], rows)


def bench_trials(goal: str = "Lion") -> None:
    from sim.experiments.trial import run_trial

    rows = []
    for mode in ("geometric", "camera"):
        result = run_trial(str(ROOT / "worlds" / "zoo"), goal, perception=mode)
        rows.append([mode, goal, "found" if result.success else result.reason, f"{result.distance_m:.1f}",
                     f"{result.sim_s:.0f}", f"{result.wall_s:.1f}", f"{result.realtime_factor:.1f}"])
    table("Closed-loop zoo trial (one core)", ["perception", "goal", "outcome", "distance (m)", "simulated (s)",
                                               "wall (s)", "real-time factor"], rows)


def bench_study(trials: int = 1, workers: int = 2, perception: str = "geometric") -> None:
    from abstract_map.cli import main

    with tempfile.TemporaryDirectory() as out:
        began = time.perf_counter()
        main(["study", "--world", str(ROOT / "worlds" / "zoo"), "--trials", str(trials), "--workers", str(workers),
              "--perception", perception, "--out", out])
        wall = time.perf_counter() - began
    table("Study", ["trials per goal", "perception", "workers", "total wall (s)"],
          [[str(trials), perception, str(workers), f"{wall:.0f}"]])


TEST_SEED = 1000  # the first test building: seeds 1000-1999 are for reporting only, never tuning


def generalise_tables(records: list[dict], title: str) -> None:
    """Success, SPL, ratio to oracle and wall time per navigator and signage level, then per style."""
    from sim.experiments.summary import stats

    header = ["perception", "navigator", "{}", "trials", "success", "SPL", "ratio to oracle", "wall per trial (s)",
              "CPU per trial (s)", "wall in all (min)"]
    for column in ("signage", "style"):
        groups: dict[tuple[str, str, str], list[dict]] = {}
        for record in records:
            for value in (record.get(column) or "-", "all"):
                key = (record["perception"], record["navigator"], value)
                groups.setdefault(key, []).append(record)
        rows = []
        for (perception, navigator, value), mine in sorted(groups.items(), key=lambda kv: (kv[0][0], kv[0][1],
                                                                                          kv[0][2] == "all", kv[0][2])):
            s = stats(mine)
            rows.append([perception, navigator, value, str(s["trials"]), f"{100 * s['success']:.0f}%",
                         f"{s['spl']:.2f}", "-" if math.isnan(s["ratio"]) else f"{s['ratio']:.2f}",
                         f"{s['wall']:.1f}", "-" if math.isnan(s["cpu"]) else f"{s['cpu']:.1f}",
                         f"{sum(r.get('wall_s') or 0 for r in mine) / 60:.1f}"])
        table(f"{title}, per navigator and {column}", [h.format(column) for h in header], rows)


def finished_trials(out: Path) -> list[dict]:
    """Every trial record already written under ``out`` (both parts), for a report of what has run so far."""
    import json

    records = []
    for path in sorted(out.glob("*/trials/*/*.json")):
        try:
            records.append(json.loads(path.read_text()))
        except (OSError, ValueError):
            continue  # a file being written: counted next time
    return records


@dataclass(frozen=True)
class GeneraliseSuite:
    """The generalisation benchmark: which test buildings, navigators and caps (sized to an hour on 2 cores)."""

    buildings: int = 30  # test buildings with geometric perception (seeds 1000 on); the floor is 30
    camera_buildings: int = 10  # of those, the first ones again with the camera
    geometric: tuple[str, ...] = ("paper", "frontier", "guided")  # the paper's robot, the no-signs bound, ours
    camera: tuple[str, ...] = ("guided",)  # the default navigator, to compare camera with geometric
    max_sim_s: float = 600.0  # s of simulated time per trial: 4.8x the longest oracle's drive at full speed


def bench_generalise(suite: GeneraliseSuite = GeneraliseSuite(), workers: int = 2,
                     out: Path = ROOT / "runs" / "generalise", report_only: bool = False) -> None:
    from tqdm import tqdm

    from sim.experiments.study import StudySettings
    from sim.experiments.study_run import conduct_study

    if report_only:
        records = finished_trials(out)
        generalise_tables(records, f"Generalisation, the {len(records)} trials finished so far in {out}")
        return
    began = time.perf_counter()
    parts = [("geometric", suite.buildings, suite.geometric), ("camera", suite.camera_buildings, suite.camera)]
    records: list[dict] = []
    for perception, count, navigators in parts:
        if count < 1 or not navigators:
            continue
        settings = StudySettings(worlds=(f"generated:{TEST_SEED}-{TEST_SEED + count - 1}",), perception=perception,
                                 navigators=navigators, trials=1, max_sim_s=suite.max_sim_s)
        bar = tqdm(total=0, unit="trial", desc=perception, file=sys.stderr, dynamic_ncols=True)

        def progress(done: int, total: int, record: dict | None, bar: Any = bar) -> None:
            bar.total, bar.n = total, done
            bar.refresh()

        outcome = conduct_study(settings, out / perception, workers=workers, progress=progress)
        bar.close()
        records += outcome.records
        print(f"generalise: {perception} done, {len(outcome.records)} trials, {outcome.wall_s / 60:.1f} min",
              file=sys.stderr, flush=True)
    wall = time.perf_counter() - began
    generalise_tables(records, f"Generalisation over test buildings {TEST_SEED}-{TEST_SEED + suite.buildings - 1} "
                               f"(camera: first {suite.camera_buildings}), 1 trial per goal, cap "
                               f"{suite.max_sim_s:.0f} s, {workers} workers")
    print(f"benchmark wall time: {wall / 60:.1f} min (trials resumed from {out} not counted)")


def bench_generate(seeds: range = range(1000, 1005)) -> None:
    """Generation time per style and size (median over seeds; CPU time, which load does not inflate, and wall)."""
    from sim.world.check import check_world
    from sim.world.generator import generate
    from sim.world.styles import SIZES, STYLES

    rows = []
    for size in SIZES:
        for style in STYLES:
            cpu, wall, rooms, tags, passed = [], [], [], [], 0
            for seed in seeds:
                c0, w0 = time.process_time(), time.perf_counter()
                g = generate(seed, style=style, size=size)
                cpu.append(time.process_time() - c0)
                wall.append(time.perf_counter() - w0)
                rooms.append(len(g.layout.rooms))
                tags.append(len(g.world.tags))
                passed += check_world(g.world, hierarchy=g.hierarchy).ok
            rows.append([size, style, f"{np.median(cpu):.2f}", f"{max(cpu):.2f}", f"{np.median(wall):.2f}",
                         f"{min(rooms)}-{max(rooms)}", f"{min(tags)}-{max(tags)}", f"{passed}/{len(seeds)}"])
    table("Generate", ["size", "style", "median CPU (s)", "max CPU (s)", "median wall (s)", "rooms", "tags",
                       "pass world check"], rows)
def bench_recording(goal: str = "Kingfisher") -> None:
    from sim.experiments.recording import rerun_module
    from sim.experiments.trial import run_trial

    rerun_module()  # imported before the clocks start

    rows = []
    with tempfile.TemporaryDirectory() as out:
        for mode in ("geometric", "camera"):
            runs = {}
            for log in (None, Path(out) / f"{mode}.rrd"):
                wall, cpu = time.perf_counter(), time.process_time()
                result = run_trial(str(ROOT / "worlds" / "zoo"), goal, perception=mode, log=log)
                runs[log is not None] = (time.perf_counter() - wall, time.process_time() - cpu, result.distance_m)
            (plain_wall, plain_cpu, plain_m), (log_wall, log_cpu, log_m) = runs[False], runs[True]
            size = (Path(out) / f"{mode}.rrd").stat().st_size
            rows.append([mode, goal, f"{plain_m:.1f} / {log_m:.1f}", f"{plain_wall:.1f}", f"{log_wall:.1f}",
                         f"{100 * (log_wall / plain_wall - 1):+.0f}", f"{100 * (log_cpu / plain_cpu - 1):+.0f}",
                         f"{size / 1e6:.1f}"])
    table("Recording a zoo trial (--log): cost and size", ["perception", "goal", "distance without / with (m)",
                                                            "wall without (s)", "wall with (s)", "wall overhead (%)",
                                                            "CPU overhead (%)", "file (MB)"], rows)


BENCHMARKS: dict[str, Callable[[], None]] = {"settle": bench_settle, "scaling": bench_scaling,
                                             "trials": bench_trials, "study": bench_study,
                                             "generate": bench_generate, "recording": bench_recording}
NAMED_ONLY = ("generalise",)  # too long for the default set; run by name


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("which", nargs="*",
                        help=f"benchmarks to run, of {sorted([*BENCHMARKS, *NAMED_ONLY])} "
                             f"(default: {sorted(BENCHMARKS)})")
    suite = GeneraliseSuite()
    parser.add_argument("--buildings", type=int, default=suite.buildings,
                        help=f"generalise: test buildings, geometric (default {suite.buildings})")
    parser.add_argument("--camera-buildings", type=int, default=suite.camera_buildings,
                        help=f"generalise: of those, how many with the camera (default {suite.camera_buildings})")
    parser.add_argument("--max-sim-s", type=float, default=suite.max_sim_s,
                        help=f"generalise: cap on each trial's simulated seconds (default {suite.max_sim_s:.0f})")
    parser.add_argument("--workers", type=int, default=2, help="generalise: parallel trials (default 2)")
    parser.add_argument("--out", type=Path, default=ROOT / "runs" / "generalise",
                        help="generalise: study folder, re-used to resume (default runs/generalise)")
    parser.add_argument("--report-only", action="store_true",
                        help="generalise: tabulate the trials finished so far in --out; run nothing")
    args = parser.parse_args()
    unknown = [w for w in args.which if w not in BENCHMARKS and w not in NAMED_ONLY]
    if unknown:
        parser.error(f"unknown benchmark(s) {unknown}; choose from {sorted([*BENCHMARKS, *NAMED_ONLY])}")
    if not (1 <= args.buildings <= 1000 and 0 <= args.camera_buildings <= args.buildings and args.workers >= 1
            and 1.0 <= args.max_sim_s <= 1e6):
        parser.error("--buildings must be 1-1000, --camera-buildings 0 to --buildings, --workers at least 1, "
                     "--max-sim-s 1 to 1000000")
    for name in args.which or BENCHMARKS:
        if name == "generalise":
            chosen = replace(suite, buildings=args.buildings, camera_buildings=args.camera_buildings,
                             max_sim_s=args.max_sim_s)
            bench_generalise(chosen, args.workers, args.out, args.report_only)
        else:
            BENCHMARKS[name]()
    return 0


if __name__ == "__main__":
    sys.exit(main())
