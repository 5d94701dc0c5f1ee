"""Replay a scenario of cues and write the imagined map after each settle.

Example:
  abstract-map imagine worlds/zoo/lion_replay.json --out r.json --plot lion.png

Writes {"steps": [{"settled", "stopped_by", "iterations", "wall_s", "positions",
"goal"}, ...]}, the first entry being the model of the hierarchy alone.
"stopped_by" says which cap ended a settle that did not come to rest ("steps"
or "time"; "" when it settled). Prints one progress line per step and the
median settle time.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path
from typing import Any

from . import errors
from .cli import distinct_outputs, output_file
from .files import write_text_atomic
from .model import settle_caps
from .scenario import load_scenario, replay

PLOT_SUFFIXES = ("png", "pdf", "svg", "jpg", "jpeg")

SUMMARY = "replay a scenario of cues and write the imagined map after each"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scenario", type=Path, help="scenario JSON (hierarchy, start, optional goal, steps)")
    parser.add_argument("--out", type=Path, required=True, help="where to write the result JSON")
    parser.add_argument("--plot", type=Path, help="also draw the final imagined map to this PNG")
    parser.add_argument("--save-model", type=Path, help="also save the final model (versioned JSON)")
    parser.add_argument("--max-steps", type=int, help="cap each settle at this many steps (default: the model's "
                        "max_iterations, 50,000)")
    parser.add_argument("--max-s", type=float, help="cap each settle at this many seconds of wall time (default: "
                        "none)")
    parser.add_argument("--quiet", action="store_true", help="no progress lines")


def run(args: argparse.Namespace) -> int:
    output_file("--out", args.out)
    if args.plot is not None:
        output_file("--plot", args.plot, suffixes=PLOT_SUFFIXES)
    if args.save_model is not None:
        output_file("--save-model", args.save_model)
    distinct_outputs(scenario=args.scenario, **{"--out": args.out, "--plot": args.plot,
                                                "--save-model": args.save_model})
    settle_caps(args.max_steps, args.max_s, names=("--max-steps", "--max-s"), error=errors.AbstractMapError)
    scenario = load_scenario(args.scenario)

    def progress(i: int, n: int, record: dict[str, Any]) -> None:
        if not args.quiet:
            goal = "" if record["goal"] is None else " goal ({:.2f}, {:.2f})".format(*record["goal"])
            state = "settled" if record["settled"] else f"NOT settled (the {record['stopped_by']} cap)"
            print(f"[{i}/{n}] {record['cue']}: {state} in {record['iterations']} steps, "
                  f"{record['wall_s'] * 1000:.1f} ms{goal}", file=sys.stderr)

    model, records = replay(scenario, progress=progress, max_steps=args.max_steps, max_s=args.max_s)
    write_text_atomic(args.out, json.dumps({"scenario": str(args.scenario), "steps": records}, indent=1,
                                           allow_nan=False))
    if args.plot:
        from .drawing import save_picture

        save_picture(model, args.plot, title=f"{args.scenario.name}: imagined map after {len(records) - 1} cues")
    if args.save_model:
        from .persistence import save

        save(model, args.save_model)
    if not args.quiet:
        median = statistics.median(r["wall_s"] for r in records[1:]) if len(records) > 1 else records[0]["wall_s"]
        print(f"wrote {args.out}; median settle {median * 1000:.1f} ms over {len(records) - 1} steps",
              file=sys.stderr)
    return 0
