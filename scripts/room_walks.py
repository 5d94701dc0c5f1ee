"""Metres walked inside rooms, by whose rooms they are: the goal's own area, a room the goal is reached
through, or another area's; and whether the label beside the room's door had been read before the robot went
in.

Usage: python scripts/room_walks.py STUDY_DIR [STUDY_DIR ...]

Each STUDY_DIR is a study folder of generated buildings (``abstract-map study --world generated:A-B``); the
rooms are the generator's plan of each building (``sim.world.layout``), the walks each trial's trajectory.
Prints metres per trial (all trials of all folders) walked inside the free part of rooms of each kind
(docs/method-notes.md, "Rooms behind doors labelled with another area's place").
"""

from __future__ import annotations

import sys
from collections import Counter
from functools import cache
from pathlib import Path

import numpy as np

from sim.experiments.compare import CompareError, load_records
from sim.world.generator import generate
from sim.world.layout import Layout, Room


def inside(rect: tuple[float, float, float, float], xy: np.ndarray) -> np.ndarray:
    """Whether each point ``xy`` ((N, 2) m) lies in ``rect`` (x0, y0, x1, y1 m)."""
    x0, y0, x1, y1 = rect
    return (xy[:, 0] >= x0) & (xy[:, 0] <= x1) & (xy[:, 1] >= y0) & (xy[:, 1] <= y1)


def kind_of(room: Room, goal: Room, rooms: dict[str, Room]) -> str:
    """Whose room ``room`` is, seen from the search for ``goal``."""
    hosts, via = set(), goal.via
    while via:
        hosts.add(via)
        via = rooms[via].via
    if room.name in hosts:
        return "a room the goal is reached through"
    return "the goal's area" if room.area == goal.area else "another area's"


@cache
def plan(world: str, style: str, signage: str) -> Layout:
    """The generator's plan of the building ``world`` (``gen-STYLE-SIZE-SIGNAGE[-ARROWS]-SEED``)."""
    parts = world.split("-")
    return generate(int(parts[-1]), style=style, size=parts[2], signage=signage).layout


def main(argv: list[str]) -> int:
    if not argv:
        print(__doc__.strip().splitlines()[0] + "\nusage: python scripts/room_walks.py STUDY_DIR [STUDY_DIR ...]")
        return 2
    walked: Counter[tuple[str, str]] = Counter()
    trials = 0
    for study in map(Path, argv):
        try:
            records = load_records(study)
        except CompareError as exc:
            print(f"room_walks: {exc}")
            return 2
        for result in records:
            rooms = {r.name: r for r in plan(result["world"], result["style"], result["signage"]).rooms}
            trials += 1
            goal = rooms.get(result["goal"])
            if goal is None:
                continue
            path = np.array(result["trajectory"])[:, 1:3]
            step = np.hypot(*np.diff(path, axis=0).T)
            at_m = np.concatenate([[0.0], np.cumsum(step)])
            middle = (path[1:] + path[:-1]) / 2
            read: dict[str, float] = {}
            for cue in result["cues"]:
                read.setdefault(cue["text"], cue["distance_m"])
            for room in rooms.values():
                within = inside(room.free, middle)
                if room is goal or not within.any():
                    continue
                door = room
                while door.via:
                    door = rooms[door.via]
                entered = at_m[int(np.argmax(within))]
                before = read.get(door.name, np.inf) <= entered + 0.5
                walked[(kind_of(room, goal, rooms), "read before" if before else "not read before")] += \
                    float(step[within].sum())
    print(f"{trials} trials; metres per trial walked inside rooms other than the goal's")
    print("| whose room | its door's label read before going in | not read before |")
    print("|---|---|---|")
    for kind in ("the goal's area", "a room the goal is reached through", "another area's"):
        before, after = walked[(kind, "read before")] / trials, walked[(kind, "not read before")] / trials
        print(f"| {kind} | {before:.1f} | {after:.1f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
