"""Run one closed-loop trial, headless, in a pybullet world.

Example:
  abstract-map trial --world zoo --goal Lion --out runs/lion
  abstract-map trial --world zoo --goal Toilets --perception geometric --seed 3 --out runs/t3 --record
  abstract-map trial --world zoo --goal Lion --navigator frontier --perception geometric --out runs/f
  abstract-map trial --world zoo --goal Lion --navigator viewpoint --out runs/lion-viewpoint --record
  abstract-map trial --world zoo --goal Kingfisher --out runs/k --log runs/k/run.rrd   (then: rerun runs/k/run.rrd)

Prints a live progress line (simulated time, distance, cues read), then writes
DIR/result.json (goal, success, reason, and for a failure its explanation: why the
goal's label went unread, such as "passed edge-on: nearest 0.8 m at 231 s, 70 deg
off its facing"; distance_m, simulated and wall seconds, cues read in order with the
distance at each, the trajectory) and DIR/trajectory.png (floor plan, path, tags read, final imagined places).
--record also writes DIR/run.gif, an animation of the robot, the explored map
and the abstract map (with --navigator viewpoint or guided also the goal belief, magenta,
and the swept space, blue). --log FILE.rrd writes a rerun recording on the
simulated-time line (needs the [viz] extra). Exit code 0 when the goal was found, 1 when the trial
failed (the reason is in result.json), 2 on bad input.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from abstract_map.cli import ExitError, output_folder
from abstract_map.errors import integer, number, place_name
from abstract_map.files import json_text, write_text_atomic
from sim.navigation.names import DEFAULT_NAVIGATOR, navigator_help

SUMMARY = "run one closed-loop trial in a pybullet world (needs the [sim] extra)"
EXTRA = "sim"  # the optional dependencies it needs


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--world", default="zoo", help="a world folder or a name under worlds/ (default: zoo)")
    parser.add_argument("--goal", required=True, help="the place to find, e.g. Lion")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument("--perception", default="camera", choices=["camera", "geometric"],
                        help="rendered camera + OpenCV AprilTag detector, or the fast geometric check")
    parser.add_argument("--navigator", default=DEFAULT_NAVIGATOR,
                        help=f"navigation policy: {navigator_help(DEFAULT_NAVIGATOR)}")
    parser.add_argument("--out", type=Path, required=True, help="output folder")
    parser.add_argument("--record", action="store_true", help="also write DIR/run.gif, an animation of the run")
    parser.add_argument("--log", type=Path, metavar="FILE.rrd",
                        help="also write a rerun recording of the run (open it with: rerun FILE.rrd; needs [viz])")
    parser.add_argument("--max-sim-s", type=float, default=None, help="cap on simulated seconds (default 900)")


def check_arguments(args: argparse.Namespace) -> None:
    """Every argument checked before any work: ExitError (exit 2) naming the first bad one."""
    output_folder("--out", args.out)
    if args.max_sim_s is not None:
        number("--max-sim-s", args.max_sim_s, low=1.0, high=1e6, error=ExitError)
    integer("--seed", args.seed, low=0, high=2**32, error=ExitError)
    place_name("--goal", args.goal, error=ExitError)


def run(args: argparse.Namespace) -> int:
    from dataclasses import replace

    from sim.world.data import load_world

    check_arguments(args)  # before the simulator is imported: a bad argument costs nothing
    world = load_world(args.world)
    if not world.label_tags(args.goal):
        raise ExitError(f"--goal {args.goal!r}: no label names it in {world.name}; goals: {sorted(world.goals)}")

    from sim.experiments.pictures import animation, trajectory_picture
    from sim.experiments.recording import MissingExtraError, rerun_module
    from sim.experiments.trial import TrialParams, run_trial
    from sim.navigation.policies import NAVIGATORS

    if args.navigator not in NAVIGATORS:
        raise ExitError(f"--navigator {args.navigator!r}: expected one of {', '.join(NAVIGATORS)}")
    if args.log is not None:
        try:
            rerun_module()
        except MissingExtraError as exc:
            raise ExitError(str(exc)) from exc
    params = TrialParams()
    if args.max_sim_s is not None:
        params = replace(params, max_sim_s=args.max_sim_s)
    live = sys.stderr.isatty()

    def progress(t: float, distance: float, cues: int) -> None:
        line = f"{args.goal}: sim {t:6.1f} s | {distance:6.1f} m | {cues:2d} cues read"
        if live:
            print(f"\r{line}", end="", file=sys.stderr, flush=True)
        elif int(t) % 10 == 0:
            print(line, file=sys.stderr, flush=True)

    try:
        result = run_trial(world, args.goal, seed=args.seed, perception=args.perception,
                           navigator=args.navigator, params=params,
                           progress=progress, record=args.record, log=args.log)
    except ValueError as exc:
        raise ExitError(str(exc)) from exc
    if live:
        print(file=sys.stderr)
    write_text_atomic(args.out / "result.json", json_text(result.to_dict(), indent=1))
    trajectory_picture(result, world, args.out / "trajectory.png")
    if args.record:
        animation(result, world, args.out / "run.gif")
    verdict = "FOUND" if result.success else f"FAILED ({result.reason}; {result.explanation})"
    print(f"{args.goal}: {verdict} after {result.distance_m:.1f} m, {result.sim_s:.0f} s simulated in "
          f"{result.wall_s:.0f} s wall ({result.realtime_factor:.1f}x real time); wrote {args.out}/",
          file=sys.stderr)
    return 0 if result.success else 1
