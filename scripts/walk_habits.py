"""How the walks of one or more studies moved: turning round, ground walked again, weaving and doorways.

Usage: ``python scripts/walk_habits.py DIR [DIR ...] [--by FIELD]``: each ``DIR`` a study folder
(``DIR/trials/WORLD/*.json``; a ``generalise`` folder's parts, ``DIR/geometric`` and ``DIR/camera``, are study
folders too). Worlds are read from ``DIR/worlds/WORLD`` (generated buildings) or by name (``zoo``). One row per
navigator (and per value of ``--by``: signage, style, role, perception, success), and one for the oracle's
own paths to the same goals: walks, metres walked per walk, turnarounds per 100 m, the share of the walk
over ground already walked and the share woven beyond the chord on nearly straight stretches (%), and per
walk the doorways passed (into a room or out of one), passed again (a room entered again) and entered from
the side of a plate beside them before it was read (over the walks that record what they read: not the
oracle's, nor those of navigators that read no sign). These are the failure modes issue 10 names, counted
from the true path and the floor plan (:mod:`sim.experiments.habits`).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from tqdm import tqdm

from abstract_map.errors import AbstractMapError
from sim.experiments.compare import CompareError, load_records, study_world
from sim.experiments.habits import habits_table, study_habits
from sim.world.data import World

BY = ("signage", "style", "role", "perception", "success")


def study_folders(folder: Path) -> list[Path]:
    """``folder`` itself when it holds trials, else its parts that do (a ``generalise`` run's)."""
    if (folder / "trials").is_dir():
        return [folder]
    return sorted(part for part in folder.iterdir() if (part / "trials").is_dir()) if folder.is_dir() else []


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folders", nargs="+", type=Path, help="study folders (or generalise run folders)")
    parser.add_argument("--by", choices=BY, help="also split each navigator's walks by this field")
    args = parser.parse_args(argv)
    records: list[dict] = []
    worlds: dict[str, World] = {}
    for folder in args.folders:
        parts = study_folders(folder)
        if not parts:
            parser.exit(2, f"walk_habits: {folder}: no trial records (expected DIR/trials/WORLD/*.json)\n")
        for part in parts:
            try:
                found = load_records(part)
            except CompareError as error:
                parser.exit(2, f"walk_habits: {error}\n")
            for name in sorted({r["world"] for r in found} - set(worlds)):
                try:
                    worlds[name] = study_world([part], name)
                except AbstractMapError as error:
                    parser.exit(2, f"walk_habits: world {name!r} of {part}: {error}\n")
            records += found
    rows, unmeasured = study_habits(tqdm(records, desc="walks", unit="walk", file=sys.stderr), worlds,
                                    (lambda r: str(r.get(args.by))) if args.by else (lambda r: "all"))
    print("\n".join(habits_table(rows, args.by or "group")))
    if unmeasured:
        print(f"\n{unmeasured} walk(s) carried no trajectory to measure", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
