"""Benchmarks of abstract-map, printed as tables.

Run from the repository root:

    python benchmarks/run.py                  # everything (about 10 minutes on 2 cores)
    python benchmarks/run.py settle scaling   # just some of: settle, scaling, trials, study

settle   median settle time per cue on the Lion replay (the authors' code: 1.5-5.6 s)
scaling  settle time as the model grows: synthetic hierarchies of about 50, 500, 5,000 places with cues
         (a few minutes: the 5,000-place model takes about 13 ms per integration step)
trials   wall time and real-time factor of the Lion trial, per perception mode
study    total wall time of a small study (1 trial per goal, geometric, 2 workers)
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
from pathlib import Path

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
                                             "recording": bench_recording}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("which", nargs="*", help=f"benchmarks to run, of {sorted(BENCHMARKS)} (default: all)")
    args = parser.parse_args()
    unknown = [w for w in args.which if w not in BENCHMARKS]
    if unknown:
        parser.error(f"unknown benchmark(s) {unknown}; choose from {sorted(BENCHMARKS)}")
    for name in args.which or BENCHMARKS:
        BENCHMARKS[name]()
    return 0


if __name__ == "__main__":
    sys.exit(main())
