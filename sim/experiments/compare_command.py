"""Compare two studies trial by trial: the change of success and SPL, with its standard error, by group.

Examples:
  abstract-map compare runs/main runs/change
  abstract-map compare runs/dev runs/dev --navigators paper guided
  abstract-map compare runs/main runs/change --by signage,style,world --out runs/change/against-main.md

Pairs the trials both study folders ran (same world, goal, seed and perception,
and the same navigator unless --navigators names one for each side, which may
then be one folder) and prints a Markdown report: per group (all, then each
value of each --by field), the trials found by each side, the mean SPL of each,
the mean change per trial with its standard error (a change under two standard
errors is within the spread of single trials), the geometric mean ratio of
the walks found by both and how many walks went the same way; then where the
found walks went (far, near but unseen, seen but unread: mean metres per found
trial) and the trials that only one side ran. --out also writes the report to a file. Exit code 2 on bad input
(a missing folder, unreadable records, no shared trial).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from abstract_map.cli import ExitError, output_file
from abstract_map.files import write_text_atomic

SUMMARY = "compare two studies trial by trial: change of success and SPL with its standard error (needs [sim])"
EXTRA = "sim"  # the optional dependencies it needs
FIELDS = ("signage", "style", "role", "world", "goal", "navigator", "perception", "seed")  # what --by may name


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("base", type=Path, help="the study folder to compare against (abstract-map study --out)")
    parser.add_argument("new", type=Path, help="the study folder with the change")
    parser.add_argument("--navigators", nargs=2, metavar=("BASE", "NEW"),
                        help="compare navigator BASE of the first folder with NEW of the second (the same "
                             "folder twice compares two navigators of one study)")
    parser.add_argument("--by", default="signage,style",
                        help=f"comma list of the fields to group by after 'all' (default signage,style; any of "
                             f"{', '.join(FIELDS)}; 'none' for 'all' only)")
    parser.add_argument("--out", type=Path, metavar="FILE.md", help="also write the report to this file")


def run(args: argparse.Namespace) -> int:
    from sim.experiments.compare import CompareError, compare, load_records, markdown

    groups = [] if args.by.strip() == "none" else [g.strip() for g in args.by.split(",") if g.strip()]
    unknown = [g for g in groups if g not in FIELDS]
    if unknown:
        raise ExitError(f"--by {args.by!r}: unknown field {unknown[0]!r} (expected any of {', '.join(FIELDS)})")
    out = output_file("--out", args.out, suffixes=("md",)) if args.out is not None else None
    for flag, folder in (("base", args.base), ("new", args.new)):
        if not folder.is_dir():
            raise ExitError(f"{flag} {str(folder)!r}: not a folder (expected a study folder)")
    base_nav, new_nav = args.navigators if args.navigators else (None, None)
    try:
        result = compare(load_records(args.base, base_nav), load_records(args.new, new_nav), groups=groups,
                         with_navigator=args.navigators is None)
    except CompareError as exc:
        raise ExitError(str(exc)) from exc
    names = (f"{args.base} ({base_nav})", f"{args.new} ({new_nav})") if args.navigators else (str(args.base),
                                                                                          str(args.new))
    text = markdown(result, *names)
    print(text, end="")
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
        write_text_atomic(out, text)
    return 0
