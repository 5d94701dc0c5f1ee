"""Benchmarks of abstract-map, printed as tables.

Run from the repository root:

    python benchmarks/run.py                  # settle, campus, trials, study, generate, recording
    python benchmarks/run.py settle campus    # just some of them
    python benchmarks/run.py settle --against main   # the Lion replay on this checkout and on main, side by side
    python benchmarks/run.py generalise       # the generalisation benchmark (within an hour on 2 cores)
    python benchmarks/run.py generalise --buildings 6 --camera-buildings 2   # a quick run

settle   median CPU time per settle on the Lion replay (the authors' code: 1.5-5.6 s), steps, whether each
         settle converged and how far the imagined Lion ends from its tag. --against REF also runs it on the
         git ref REF (a temporary git worktree on PYTHONPATH) and prints the ratio of medians.
campus   a robot walking a generated campus (benchmarks/campus.py), one cue at a time with a settle after
         each: 500 and 5,000 places, each the whole walk (--cues N for the first N). Median and p95 settle,
         places moved, converged settles, peak memory, imagined-position error of places named but not yet seen.
campus20k  the same at 20,000 places (the whole walk, about an hour; --cues N for fewer); named only
trials   wall time and real-time factor of the Lion trial, per perception mode
study    total wall time of a small study (1 trial per goal, geometric, 2 workers)
generate time to generate a building per style and size, and how many pass the world check
generalise  test buildings (seeds 1000-1029, medium, styles and signage levels cycling), 5 goals each,
         geometric perception, navigators paper, frontier, guided, even-prior (guided without the abstract
         map's imagined goal), known-goal (guided told where the goal's label hangs) and known-pose (driven
         straight to the front of that label: the informed point-goal reference); then 10 of them (1000-1009)
         with the camera and the guided navigator; each trial capped at 600 s simulated. Success, SPL, ratio to oracle
         and wall time per navigator and signage level, per style and per goal role.
         A resumable study folder (--out, default runs/generalise); named only, never part of the default set.
recording  what a rerun recording (--log) costs: the Kingfisher trial with and without it, per perception mode
           (needs the viz extra)
"""

from __future__ import annotations

import argparse
import contextlib
import math
import statistics
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
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


LION_TAG_XY = (-21.6996, 17.703)  # m, the Lion's label in worlds/zoo/tags.json (tag 17)


def measure_in(checkout: Path, script: str, *args: str) -> dict:
    """Run benchmarks/``script`` in a child process on ``checkout``'s code (one BLAS thread) and return the JSON
    of its last line, after checking that it measured that checkout's abstract_map (its ``module``)."""
    import json
    import os
    import subprocess

    env = {**os.environ, "PYTHONPATH": str(checkout), "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    out = subprocess.run([sys.executable, str(ROOT / "benchmarks" / script), *args],
                         env=env, cwd=checkout, capture_output=True, text=True, check=True)
    result = json.loads(out.stdout.strip().splitlines()[-1])
    if not Path(result["module"]).resolve().is_relative_to(checkout.resolve()):
        raise RuntimeError(f"measured {result['module']}, not the checkout {checkout}")
    return result


def lion_settles(checkout: Path, runs: int = 3) -> dict:
    """The Lion replay's settles timed (CPU s) with ``checkout``'s abstract_map, in a child process."""
    result = measure_in(checkout, "lion_settles.py", str(ROOT / "worlds" / "zoo" / "lion_replay.json"), str(runs))
    per_cue = [statistics.median(run[i] for run in result["cpu_s"]) for i in range(len(result["cpu_s"][0]))]
    result["per_cue"] = per_cue
    result["median"] = statistics.median(per_cue)
    result["lion_m"] = math.dist(result["goal"], LION_TAG_XY)
    return result


@contextlib.contextmanager
def checkout(ref: str) -> Iterator[Path]:
    """Git ref ``ref`` of this repository in a temporary worktree, removed afterwards."""
    import subprocess

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "ref"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(path), ref],
                       check=True, capture_output=True)
        try:
            yield path
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(path)],
                           check=False, capture_output=True)


def bench_settle(against: str | None = None, runs: int = 3) -> None:
    """Median CPU per settle on the Lion replay; with ``against``, also on that git ref, side by side."""
    results = {"this checkout": lion_settles(ROOT, runs)}
    if against:
        with checkout(against) as ref_dir:
            results[against] = lion_settles(ref_dir, runs)
            results["this checkout"] = lion_settles(ROOT, runs)  # again, after: load shared alike
    names = list(results)
    rows = []
    for i in range(len(results[names[0]]["per_cue"])):
        rows.append([str(i + 1)] + [f"{results[n]['per_cue'][i] * 1000:.1f} ({results[n]['steps'][i]})"
                                    for n in names])
    rows.append(["median"] + [f"{results[n]['median'] * 1000:.1f}" for n in names])
    rows.append(["settled"] + [f"{sum(results[n]['settled'])}/{len(results[n]['settled'])}" for n in names])
    rows.append(["Lion from its tag (m)"] + [f"{results[n]['lion_m']:.2f}" for n in names])
    table(f"CPU ms per settle (steps), Lion replay, median of {runs} runs", ["cue", *names], rows)
    low, high = AUTHORS_SETTLE_S
    median = results["this checkout"]["median"]
    print(f"authors' implementation: {low}-{high} s per settle -> {low / median:.0f}x to {high / median:.0f}x faster")
    if against:
        print(f"median settle ratio {against} / this checkout: {results[against]['median'] / median:.2f}")


CAMPUS_CUES = {500: None, 5000: None, 20000: None}  # cues walked per size (None: the whole walk); --cues N


def campus_walk(checkout_dir: Path, n: int, cues: int | None) -> dict:
    """benchmarks/campus.py at ``n`` places with ``checkout_dir``'s abstract_map, in a child process."""
    return measure_in(checkout_dir, "campus.py", str(n), "--json", *([] if cues is None else ["--cues", str(cues)]))


def bench_campus(sizes: tuple[int, ...] = (500, 5000), cues: int | None = None, against: str | None = None) -> None:
    """The campus walk (benchmarks/campus.py), one child process per size so peak memory is its own."""
    runs: list[tuple[str, Path]] = [("this checkout", ROOT)]
    with contextlib.ExitStack() as stack:
        if against:
            runs.append((against, stack.enter_context(checkout(against))))
        rows = []
        for n in sizes:
            for name, path in runs:
                f = campus_walk(path, n, cues if cues is not None else CAMPUS_CUES.get(n))
                print(f"campus: {n} places done ({name})", file=sys.stderr, flush=True)
                caps = f["caps"]
                rows.append([name, str(f["places"]), f"{f['cues']}/{f['of_cues']}",
                             f"{f['first_settle_cpu_s']:.1f}", f"{f['median_cpu_ms']:.0f}",
                             f"{f['p95_cpu_ms']:.0f}", str(int(f["median_steps"])),
                             str(int(f.get("median_moved", f["places"]))),
                             f"{f['converged']}/{f['cues']}" + (f" ({caps['time']} at the time cap)"
                                                                if caps.get("time") else ""),
                             f"{f['peak_mb']:.0f}", f"{f['error_median_m']:.1f} / {f['guess_median_m']:.1f}"])
    table("Campus walk: one cue at a time, a settle after each (CPU time)", [
        "code", "places", "cues walked", "hierarchy settle (s)", "median ms/settle", "p95 ms", "median steps",
        "median places moved", "converged", "peak MB", "named, unseen: median error / guess at sign (m)"], rows)


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
    """Success, SPL, ratio to oracle and wall time per navigator and signage level, then per style, then per
    goal role (why the generator chose the goal: ``goal_roles``)."""
    from sim.experiments.summary import stats

    header = ["perception", "navigator", "{}", "trials", "success", "SPL", "ratio to oracle", "wall per trial (s)",
              "CPU per trial (s)", "wall in all (min)"]  # costs count a shared run once (run_cost)
    for column in ("signage", "style", "role"):
        groups: dict[tuple[str, str, str], list[dict]] = {}
        for record in records:
            for value in (record.get(column) or "-", "all"):
                key = (record["perception"], record["navigator"], value)
                groups.setdefault(key, []).append(record)
        rows = []
        for (perception, navigator, value), mine in sorted(groups.items(), key=lambda kv: (kv[0][0], kv[0][1],
                                                                                          kv[0][2] == "all", kv[0][2])):
            s = stats(mine)
            wall, cpu = run_cost(mine, "wall_s"), run_cost(mine, "cpu_s")
            rows.append([perception, navigator, value, str(s["trials"]), f"{100 * s['success']:.0f}%",
                         f"{s['spl']:.2f}", "-" if math.isnan(s["ratio"]) else f"{s['ratio']:.2f}",
                         f"{wall / len(mine):.1f}", f"{cpu / len(mine):.1f}", f"{wall / 60:.1f}"])
        table(f"{title}, per navigator and {column}", [h.format(column) for h in header], rows)
    explained_failures(records, title)
    walk_phases(records, title)


def walk_habits(records: list[dict], out: Path, title: str) -> None:
    """How the walks moved (``sim.experiments.habits``) per navigator and perception, beside the oracle's paths,
    the worlds read from the run's own ``out/PART/worlds/`` (``sim.experiments.compare.study_world``)."""
    from sim.experiments.compare import study_world
    from sim.experiments.habits import habits_table, study_habits
    from sim.world.data import WorldError

    parts = sorted(part for part in out.iterdir() if part.is_dir())
    worlds = {}
    for name in sorted({r["world"] for r in records}):
        try:
            worlds[name] = study_world(parts, name)
        except WorldError:
            continue  # counted below as a trial without a world to measure
    rows, unmeasured = study_habits(records, worlds, lambda r: r["perception"])
    print(f"\n{title}, how the walks moved")
    print("\n".join(habits_table(rows, "perception")))
    if unmeasured:
        print(f"({unmeasured} trial(s) without a walk or a world to measure)")


def walk_phases(records: list[dict], title: str) -> None:
    """Where the walking went (``sim.experiments.walk``) per perception, navigator and signage level."""
    from sim.experiments.summary import WALK_HEADER, walk_rows

    rows = walk_rows(records, lambda r: (r["perception"], r["navigator"], r.get("signage") or "-"))
    if rows:
        table(f"{title}, where the walking went (mean m per trial)", ["perception", "navigator", "signage",
                                                                      *WALK_HEADER], rows)


def explained_failures(records: list[dict], title: str) -> None:
    """Failed trials per perception and navigator, by their explanation (``sim.experiments.diagnosis.KINDS``)."""
    from collections import Counter

    from sim.experiments.diagnosis import KINDS
    from sim.experiments.summary import explanation_kind

    counts = Counter((r["perception"], r["navigator"], explanation_kind(r)) for r in records if not r["success"])
    kinds = [kind for kind in (*KINDS, "-") if any(key[2] == kind for key in counts)]
    pairs = sorted({key[:2] for key in counts})
    rows = [[perception, navigator, str(sum(counts[(perception, navigator, k)] for k in kinds)),
             *[str(counts[(perception, navigator, k)]) for k in kinds]] for perception, navigator in pairs]
    table(f"{title}, failures explained", ["perception", "navigator", "failed", *kinds], rows)


def run_cost(records: list[dict], field: str) -> float:
    """The summed ``field`` (s) of the runs behind ``records``: the records of a goal-blind navigator in one world,
    seed and perception come from one shared run, whose cost is its longest record's (they end as goals are read)."""
    from sim.navigation.policies import NAVIGATORS

    runs: dict[tuple, float] = {}
    for k, record in enumerate(records):
        blind = getattr(NAVIGATORS.get(record["navigator"]), "goal_blind", False)
        key = (record["world"], record["navigator"], record.get("seed"), record["perception"]) if blind else (k,)
        runs[key] = max(runs.get(key, 0.0), float(record.get(field) or 0.0))
    return sum(runs.values())


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
    """The generalisation benchmark: which test buildings, navigators and caps (59.2 min measured on 2 idle cores
    before known-goal joined; its 150 trials took 7.2 min more, and even-prior's about 10 min)."""

    buildings: int = 30  # test buildings with geometric perception (seeds 1000 on); the floor is 30
    camera_buildings: int = 10  # of those, the first ones again with the camera
    geometric: tuple[str, ...] = ("paper", "frontier", "guided", "even-prior", "known-goal", "known-pose")  # the
    # paper's robot, the no-signs bound, ours, ours without the abstract map's imagined goal (what the model's point
    # is worth here), ours told where the goal's label hangs (what the building alone costs this search) and a
    # point-goal planner told that and its facing (what the building costs a navigator told the goal)
    camera: tuple[str, ...] = ("guided",)  # ours, to compare camera with geometric on the same trials
    max_sim_s: float = 600.0  # s of simulated time per trial: 4.8x the longest oracle's drive at full speed
    style: str | None = None  # None: styles cycle with the seed (the test split); a name fixes every building's,
    # e.g. "park", which is outside the cycle
    arrows: str = "way"  # what the signs' arrows point along: "way" (the test split) or "bearing" (fingerposts)

    def worlds(self, count: int) -> str:
        """The ``--world`` spec of the first ``count`` test buildings."""
        options = [f"style={self.style}"] * bool(self.style) + [f"arrows={self.arrows}"] * (self.arrows != "way")
        return f"generated:{TEST_SEED}-{TEST_SEED + count - 1}" + (":" + ",".join(options) if options else "")


def bench_generalise(suite: GeneraliseSuite = GeneraliseSuite(), workers: int = 2,
                     out: Path = ROOT / "runs" / "generalise", report_only: bool = False) -> None:
    from tqdm import tqdm

    from sim.experiments.study import StudySettings
    from sim.experiments.study_run import conduct_study

    if report_only:
        records = finished_trials(out)
        generalise_tables(records, f"Generalisation, the {len(records)} trials finished so far in {out}")
        walk_habits(records, out, "Generalisation")
        return
    began = time.perf_counter()
    parts = [("geometric", suite.buildings, suite.geometric), ("camera", suite.camera_buildings, suite.camera)]
    records: list[dict] = []
    for perception, count, navigators in parts:
        if count < 1 or not navigators:
            continue
        settings = StudySettings(worlds=(suite.worlds(count),), perception=perception,
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
    generalise_tables(records, f"Generalisation over test buildings {suite.worlds(suite.buildings)} "
                               f"(camera: first {suite.camera_buildings}), 1 trial per goal, cap "
                               f"{suite.max_sim_s:.0f} s, {workers} workers")
    walk_habits(records, out, "Generalisation")
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


BENCHMARKS: dict[str, Callable[[], None]] = {"settle": bench_settle, "campus": bench_campus,
                                             "trials": bench_trials, "study": bench_study,
                                             "generate": bench_generate, "recording": bench_recording}
NAMED_ONLY = ("generalise", "campus20k")  # too long for the default set (or superseded); run by name


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
    parser.add_argument("--style", default=None,
                        help="generalise: one style for every building, e.g. park (default: styles cycle)")
    parser.add_argument("--arrows", default="way", help="generalise: what the signs' arrows point along, way "
                                                        "(default: the test split) or bearing (fingerposts)")
    parser.add_argument("--workers", type=int, default=2, help="generalise: parallel trials (default 2)")
    parser.add_argument("--out", type=Path, default=ROOT / "runs" / "generalise",
                        help="generalise: study folder, re-used to resume (default runs/generalise)")
    parser.add_argument("--report-only", action="store_true",
                        help="generalise: tabulate the trials finished so far in --out; run nothing")
    parser.add_argument("--against", metavar="REF", default=None,
                        help="settle, campus, campus20k: also run on this git ref (a temporary worktree)")
    parser.add_argument("--cues", type=int, default=None, help="campus, campus20k: cues walked per size")
    args = parser.parse_args()
    unknown = [w for w in args.which if w not in BENCHMARKS and w not in NAMED_ONLY]
    if unknown:
        parser.error(f"unknown benchmark(s) {unknown}; choose from {sorted([*BENCHMARKS, *NAMED_ONLY])}")
    if not (1 <= args.buildings <= 1000 and 0 <= args.camera_buildings <= args.buildings and args.workers >= 1
            and 1.0 <= args.max_sim_s <= 1e6):
        parser.error("--buildings must be 1-1000, --camera-buildings 0 to --buildings, --workers at least 1, "
                     "--max-sim-s 1 to 1000000")
    from sim.world.styles import STYLES
    from sim.world.truth import ARROW_READINGS

    if args.style is not None and args.style not in STYLES:
        parser.error(f"--style {args.style!r}: expected one of {', '.join(STYLES)}")
    if args.arrows not in ARROW_READINGS:
        parser.error(f"--arrows {args.arrows!r}: expected one of {', '.join(ARROW_READINGS)}")
    for name in args.which or BENCHMARKS:
        if name == "generalise":
            chosen = replace(suite, buildings=args.buildings, camera_buildings=args.camera_buildings,
                             max_sim_s=args.max_sim_s, style=args.style, arrows=args.arrows)
            bench_generalise(chosen, args.workers, args.out, args.report_only)
        elif name == "settle":
            bench_settle(args.against)
        elif name == "campus":
            bench_campus(cues=args.cues, against=args.against)
        elif name == "campus20k":
            bench_campus((20000,), cues=args.cues, against=args.against)
        else:
            BENCHMARKS[name]()
    return 0


if __name__ == "__main__":
    sys.exit(main())
