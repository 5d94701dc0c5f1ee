"""How the walks of one or more studies moved: turning round, ground walked again, weaving and doorways.

Usage: ``python scripts/walk_habits.py DIR [DIR ...] [--by FIELD]``: each ``DIR`` a study folder
(``DIR/trials/WORLD/*.json``; a ``generalise`` folder's parts, ``DIR/geometric`` and ``DIR/camera``, are study
folders too). Worlds are read from ``DIR/worlds/WORLD`` (generated buildings) or ``worlds/WORLD``. One row per
navigator (and per value of ``--by``: signage, style, role, perception, success), and one for the oracle's
own paths to the same goals: trials, metres walked per trial, turnarounds per 100 m, the share of the walk
over ground already walked and the share woven beyond the chord on nearly straight stretches (%), and per
walk the doorways passed (into a room or out of one), passed again (a room entered again) and entered from
the side of a plate beside them before it was read (over the walks that record what they read: not the
oracle's, nor those of navigators that read no sign). These are the failure modes issue 10 names, counted
from the true path and the floor plan (:mod:`sim.experiments.habits`).
"""

from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np
from tqdm import tqdm

from abstract_map.errors import AbstractMapError
from sim.experiments.compare import CompareError, load_records
from sim.experiments.habits import Habits, doorway_cells, doorway_plates, habits, totals
from sim.world.data import Floorplan, Tag, World, load_world
from sim.world.oracle import oracle_paths

ROOT = Path(__file__).resolve().parents[1]
BY = ("signage", "style", "role", "perception", "success")


def study_folders(folder: Path) -> list[Path]:
    """``folder`` itself when it holds trials, else its parts that do (a ``generalise`` run's)."""
    if (folder / "trials").is_dir():
        return [folder]
    return sorted(part for part in folder.iterdir() if (part / "trials").is_dir()) if folder.is_dir() else []


def world_folder(study: Path, name: str) -> Path:
    """Where the study's world ``name`` lies: its own ``worlds/`` first, then the repository's."""
    own = study / "worlds" / name
    return own if own.is_dir() else ROOT / "worlds" / name


def table(rows: dict[tuple[str, str], list[Habits]]) -> str:
    """A markdown table of :func:`sim.experiments.habits.totals` per (navigator, group)."""
    keys = ["turnarounds per 100 m", "revisited %", "weave %", "doorways per walk", "doorways again per walk",
            "entered unread per walk"]
    lines = ["| navigator | group | trials | walked (m) | " + " | ".join(keys) + " |",
             "|---|---|---|---|" + "---|" * len(keys)]
    for (navigator, group), walks in sorted(rows.items()):
        values = totals(walks)
        walked = sum(h.walked_m for h in walks) / len(walks)
        lines.append(f"| {navigator} | {group} | {len(walks)} | {walked:.1f} | "
                     + " | ".join(f"{values[k]:.2f}" for k in keys) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folders", nargs="+", type=Path, help="study folders (or generalise run folders)")
    parser.add_argument("--by", choices=BY, help="also split each navigator's walks by this field")
    args = parser.parse_args(argv)
    records = []
    for folder in args.folders:
        parts = study_folders(folder)
        if not parts:
            parser.exit(2, f"walk_habits: {folder}: no trial records (expected DIR/trials/WORLD/*.json)\n")
        for part in parts:
            try:
                records += [(part, r) for r in load_records(part)]
            except CompareError as error:
                parser.exit(2, f"walk_habits: {error}\n")
    worlds: dict[str, tuple[World, Floorplan, np.ndarray, dict[int, list[Tag]]]] = {}
    oracle: dict[tuple[str, str, str], Habits] = {}
    rows: dict[tuple[str, str], list[Habits]] = defaultdict(list)
    for part, record in tqdm(records, desc="walks", unit="walk", file=sys.stderr):
        name = record["world"]
        if name not in worlds:
            try:
                world = load_world(world_folder(part, name))
            except AbstractMapError as error:
                parser.exit(2, f"walk_habits: world {name!r} of {part}: {error}\n")
            plan, doorways = doorway_cells(world.floorplan)
            worlds[name] = (world, plan, doorways, doorway_plates(plan, doorways, world.tags.values()))
        world, plan, doorways, plates = worlds[name]
        trajectory = np.asarray(record.get("trajectory") or [], dtype=float)
        if trajectory.ndim != 2 or trajectory.shape[1] < 3:
            parser.exit(2, f"walk_habits: {name} {record['goal']}: the record carries no trajectory\n")
        group = str(record.get(args.by)) if args.by else "all"
        read_s: dict[int, float] | None = None  # a walk that records no read (a navigator reading no sign): unknown
        for cue in record.get("cues") or []:
            read_s = read_s if read_s is not None else {}
            read_s.setdefault(int(cue["tag_id"]), float(cue["t_s"]))
        rows[record["navigator"], group].append(habits(trajectory[:, 1:3], plan, doorways, times=trajectory[:, 0],
                                                       plates=plates, read_s=read_s))
        key = (name, record["goal"], group)
        if key not in oracle:  # once per goal and group, whichever navigators walked it
            path = oracle_paths(world, [record["goal"]])[record["goal"]].path
            oracle[key] = habits(path, plan, doorways)
            rows["oracle", group].append(oracle[key])
    print(table(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
