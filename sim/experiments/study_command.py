"""Run every goal of a world N times, and compare with the paper's humans and robot.

Example:
  abstract-map study --world zoo --trials 5 --out runs/study
  abstract-map study --world zoo --trials 200 --executor ray --address auto --out runs/big

Trials differ by seed: start-pose jitter (0.10 m, 3 deg), the recovery's
turning direction and, in geometric mode, detection noise (0.03 m, 1 deg).
Writes DIR/trials.csv (one row per trial), DIR/report.md (the paper's Table I
extended with our mean and spread, the oracle and our ratio to it),
DIR/comparison.png (box plots like the paper's Fig. 11) and DIR/paths/GOAL.png.
--log also writes a rerun recording of each trial, DIR/trials/GOAL-SEED.rrd.
A study run again on the same DIR skips the trials already finished there.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import time
from pathlib import Path
from typing import Any

from abstract_map.cli import ExitError

SUMMARY = "run every goal of a world N times and compare with the paper (needs [sim])"
EXTRA = "sim"  # the optional dependencies it needs


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--world", default="zoo", help="a world folder or a name under worlds/ (default: zoo)")
    parser.add_argument("--trials", type=int, default=5, help="trials per goal (default 5)")
    parser.add_argument("--workers", type=int, default=2, help="parallel trials (default 2)")
    parser.add_argument("--perception", default="camera", choices=["camera", "geometric"])
    parser.add_argument("--goals", nargs="+", help="only these goals (default: every goal of the world)")
    parser.add_argument("--executor", default="process", choices=["process", "ray"],
                        help="local process pool (default) or Ray (needs the [ray] extra)")
    parser.add_argument("--address", help="Ray cluster address (with --executor ray); default: a local Ray")
    parser.add_argument("--out", type=Path, required=True, help="output folder (re-use it to resume)")
    parser.add_argument("--log", action="store_true",
                        help="also write a rerun recording of each trial, DIR/trials/GOAL-SEED.rrd (needs [viz])")


def run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from sim.experiments.report import comparison_plot, goal_rows, path_pictures, report_markdown
    from sim.experiments.study import make_executor, plan_specs, run_study
    from sim.world.data import WorldError, load_world
    from sim.world.oracle import oracle_path

    if args.trials < 1 or args.workers < 1:
        raise ExitError("--trials and --workers must be at least 1")
    try:
        world = load_world(args.world)
        unknown = [g for g in (args.goals or []) if g not in world.goals]
        if unknown:
            raise ExitError(f"unknown goal(s) {unknown}; goals of {world.name}: {sorted(world.goals)}")
        executor = make_executor(args.executor, args.workers, args.address)
    except (WorldError, ValueError) as exc:
        raise ExitError(str(exc)) from exc
    specs = plan_specs(world, args.trials, args.perception, goals=args.goals)
    if args.log:
        from dataclasses import replace

        from sim.experiments.recording import MissingExtraError, rerun_module

        try:
            rerun_module()
        except MissingExtraError as exc:
            raise ExitError(str(exc)) from exc
        specs = [replace(spec, log_dir=str(args.out / "trials")) for spec in specs]
    began = time.perf_counter()
    bar = tqdm(total=len(specs), unit="trial", file=sys.stderr, dynamic_ncols=True)

    def progress(done: int, total: int, record: dict[str, Any] | None) -> None:
        bar.n = done
        if record is not None:
            verdict = f"{record['distance_m']:.1f} m" if record["success"] else "FAILED"
            bar.set_postfix_str(f"{record['goal']} seed {record['seed']}: {verdict}")
        bar.refresh()

    records = run_study(world, specs, args.out, executor=executor, progress=progress)
    bar.close()
    wall = time.perf_counter() - began
    oracles = {goal: oracle_path(world, goal) for goal in dict.fromkeys(s.goal for s in specs)}
    rows = goal_rows(world, records, oracles)
    (args.out / "report.md").write_text(report_markdown(world, rows, perception=args.perception,
                                                        trials=args.trials, wall_s=wall))
    comparison_plot(rows, args.out / "comparison.png")
    path_pictures(world, records, oracles, args.out / "paths")
    (args.out / "study.json").write_text(json.dumps({"world": world.name, "trials": args.trials,
                                                     "perception": args.perception, "workers": args.workers,
                                                     "executor": args.executor, "wall_s": round(wall, 1)}))
    reference = world.root / "paper_trials.csv"
    if reference.exists():
        shutil.copyfile(reference, args.out / "paper_trials.csv")
    print((args.out / "report.md").read_text(), file=sys.stderr)
    failed = sum(1 for r in records if not r["success"])
    print(f"{len(records) - failed}/{len(records)} trials found their goal; wrote {args.out}/", file=sys.stderr)
    return 0
