"""Run every goal of one or more worlds N times per navigator; report success, SPL and the paper's comparison.

Examples:
  abstract-map study --world zoo --trials 5 --out runs/study
  abstract-map study --world generated:0-11 --trials 1 --perception geometric --navigator paper,frontier --out runs/dev
  abstract-map study --world generated:1000-1009:style=hospital,signage=sparse --world zoo --out runs/mixed
  abstract-map study --world zoo --trials 200 --executor ray --address auto --out runs/big

--world (repeatable): a world name under worlds/, a world folder, or generated:A-B[:key=value,...]
with keys style (office, hospital, museum, campus, park), size (small, medium, large; default medium)
and signage (complete, sparse, misleading). Unless fixed, style and signage cycle with the seed: seed s
is style number s % 4 of office, hospital, museum, campus and signage level number (s // 4) % 3, so any
12 consecutive seeds cover every pair (with one fixed, the other cycles by s % its count); the park is
built only when named (style=park). arrows=bearing writes the same buildings' signs as fingerposts, each
arrow pointing at its place (default arrows=way: the way to set off). Generated worlds are written to
DIR/worlds/. Seeds 0-999 are for development; 1000-1999 are test buildings, for reporting only.

Trials differ by seed: start-pose jitter (0.10 m, 3 deg), the recovery's turning direction and, in
geometric mode, detection noise (0.03 m, 1 deg). Writes DIR/settings.json, DIR/trials/ (one JSON per
trial), DIR/trials.csv (world, style, signage, navigator, goal, role, seed, perception, success, reason,
explanation, distance_m, oracle_m, spl, near_at_m, seen_at_m, sim_s, wall_s, cpu_s), DIR/report.md (success
rate, SPL, ratio to the oracle and failures by reason: overall, per navigator, style, signage level, goal
role and world; where the walking went and how the walks moved: turnarounds, ground walked again, weave,
doorways; the ten worst trials with pictures in DIR/worst/) and, for the zoo, the paper's Table I
extended, DIR/comparison.png (box plots like the paper's Fig. 11) and DIR/paths/GOAL.png. Run again on the
same DIR to resume (across worlds): finished trials are skipped; other settings on the same DIR are refused.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from abstract_map.cli import ExitError
from sim.navigation.names import DEFAULT_NAVIGATOR, navigator_help

SUMMARY = "run every goal of one or more worlds N times per navigator and report (needs [sim])"
EXTRA = "sim"  # the optional dependencies it needs


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--world", action="append", metavar="SPEC",
                        help="a world name, a world folder or generated:A-B[:style=..,size=..,signage=..,arrows=..]; "
                             "repeatable (default: zoo)")
    parser.add_argument("--trials", type=int, default=5, help="trials per goal and navigator (default 5)")
    parser.add_argument("--navigator", action="append", metavar="NAME",
                        help=f"{navigator_help(DEFAULT_NAVIGATOR)}; repeatable or a comma list, to compare them side "
                             "by side")
    parser.add_argument("--workers", type=int, default=2, help="parallel trials (default 2)")
    parser.add_argument("--perception", default="camera", choices=["camera", "geometric"])
    parser.add_argument("--log", action="store_true",
                        help="also write a rerun recording of each trial, DIR/trials/WORLD/KEY.rrd (needs [viz])")
    parser.add_argument("--goals", nargs="+", help="only these goals (default: every goal of every world)")
    parser.add_argument("--executor", default="process", choices=["process", "ray"],
                        help="local process pool (default) or Ray (needs the [ray] extra)")
    parser.add_argument("--address", help="Ray cluster address (with --executor ray); default: a local Ray")
    parser.add_argument("--max-sim-s", type=float, default=900.0,
                        help="cap on each trial's simulated seconds (default 900)")
    parser.add_argument("--out", type=Path, required=True, help="output folder (re-use it to resume)")


def navigator_list(values: list[str] | None) -> tuple[str, ...]:
    """``--navigator`` values, repeated or comma-separated, in order, without repeats (default: DEFAULT_NAVIGATOR)."""
    names = [n.strip() for value in (values or [DEFAULT_NAVIGATOR]) for n in value.split(",") if n.strip()]
    return tuple(dict.fromkeys(names))


def run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from sim.experiments.study import StudySettings
    from sim.experiments.study_run import conduct_study

    if args.trials < 1 or args.workers < 1:
        raise ExitError("--trials and --workers must be at least 1")
    if not 1.0 <= args.max_sim_s <= 1e6:
        raise ExitError(f"--max-sim-s {args.max_sim_s}: expected 1 to 1000000 simulated seconds")
    if args.goals and len(set(args.goals)) != len(args.goals):
        raise ExitError(f"--goals {args.goals}: a goal is named twice")
    if args.log:
        from sim.experiments.recording import MissingExtraError, rerun_module

        try:
            rerun_module()
        except MissingExtraError as exc:
            raise ExitError(str(exc)) from exc
    settings = StudySettings(worlds=tuple(args.world or ["zoo"]), perception=args.perception,
                             navigators=navigator_list(args.navigator), trials=args.trials,
                             goals=tuple(args.goals) if args.goals else None, max_sim_s=args.max_sim_s)
    bars: list[Any] = []  # made at the first progress call, so a bad argument prints its one line alone

    def progress(done: int, total: int, record: dict[str, Any] | None) -> None:
        if not bars:
            bars.append(tqdm(total=total, unit="trial", file=sys.stderr, dynamic_ncols=True))
        bar = bars[0]
        bar.total, bar.n = total, done
        if record is not None:
            verdict = f"{record['distance_m']:.1f} m" if record["success"] else "FAILED"
            bar.set_postfix_str(f"{record.get('world', '')} {record.get('navigator', '')} {record['goal']} "
                                f"seed {record['seed']}: {verdict}")
        bar.refresh()

    try:
        outcome = conduct_study(settings, args.out, workers=args.workers, executor=args.executor,
                                address=args.address, progress=progress, log=args.log)
    except ValueError as exc:  # StudyError, WorldSpecError, WorldError: bad input, one line
        raise ExitError(str(exc)) from exc
    finally:
        for bar in bars:
            bar.close()
    print(outcome.report, file=sys.stderr)
    records = outcome.records
    failed = sum(1 for r in records if not r["success"])
    print(f"{len(records) - failed}/{len(records)} trials found their goal; wrote {args.out}/", file=sys.stderr)
    return 0
