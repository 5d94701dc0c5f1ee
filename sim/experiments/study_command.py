"""Run every goal of a world N times, and compare with the paper's humans and robot.

Example:
  abstract-map study --world zoo --trials 5 --out runs/study
  abstract-map study --world zoo --trials 200 --executor ray --address auto --out runs/big

Trials differ by seed: start-pose jitter (0.10 m, 3 deg), the recovery's
turning direction and, in geometric mode, detection noise (0.03 m, 1 deg).
Writes DIR/trials.csv (one row per trial), DIR/report.md (the paper's Table I
extended with our mean and spread, the oracle and our ratio to it),
DIR/comparison.png (box plots like the paper's Fig. 11) and DIR/paths/GOAL.png.
A study run again on the same DIR skips the trials already finished there.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

from abstract_map.cli import ExitError, output_folder
from abstract_map.errors import integer
from abstract_map.files import write_bytes_atomic, write_text_atomic

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


def run(args: argparse.Namespace) -> int:
    from sim.world.data import load_world

    # every argument checked before the simulator is imported: a bad one costs nothing
    integer("--trials", args.trials, low=1, high=10_001, error=ExitError)
    integer("--workers", args.workers, low=1, high=257, error=ExitError)
    output_folder("--out", args.out)
    if args.address is not None and args.executor != "ray":
        raise ExitError("--address: only with --executor ray")
    if args.goals is not None and len(set(args.goals)) < len(args.goals):
        raise ExitError(f"--goals: a goal is named twice in {args.goals}")
    world = load_world(args.world)
    unknown = [g for g in (args.goals or []) if g not in world.goals]
    if unknown:
        raise ExitError(f"--goals: unknown goal(s) {unknown}; goals of {world.name}: {sorted(world.goals)}")

    from tqdm import tqdm

    from sim.experiments.report import comparison_plot, goal_rows, path_pictures, report_markdown
    from sim.experiments.study import check_settings, make_executor, plan_specs, run_study, study_settings
    from sim.world.oracle import oracle_path

    try:
        executor = make_executor(args.executor, args.workers, args.address)
    except ValueError as exc:
        raise ExitError(str(exc)) from exc
    specs = plan_specs(world, args.trials, args.perception, goals=args.goals)
    check_settings(args.out, study_settings(world, specs))  # a resume with other settings stops here
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
    write_text_atomic(args.out / "report.md", report_markdown(world, rows, perception=args.perception,
                                                              trials=args.trials, wall_s=wall))
    comparison_plot(rows, args.out / "comparison.png")
    path_pictures(world, records, oracles, args.out / "paths")
    write_text_atomic(args.out / "study.json", json.dumps({"world": world.name, "trials": args.trials,
                                                     "perception": args.perception, "workers": args.workers,
                                                     "executor": args.executor, "wall_s": round(wall, 1)}))
    reference = world.root / "paper_trials.csv"
    if reference.exists():
        write_bytes_atomic(args.out / "paper_trials.csv", reference.read_bytes())
    print((args.out / "report.md").read_text(), file=sys.stderr)
    failed = sum(1 for r in records if not r["success"])
    print(f"{len(records) - failed}/{len(records)} trials found their goal; wrote {args.out}/", file=sys.stderr)
    return 0
