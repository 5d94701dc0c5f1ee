"""Write ``worlds/zoo/lion_replay.json``: the cues the paper's robot met finding the Lion, in order.

The paper's Lion trial (Section V-B) read tags 0-8 and 12-16 before the Lion's
label; each step carries the tag's text and its pose from ``worlds/zoo/tags.json``.
"""

from __future__ import annotations

import json
from pathlib import Path

from abstract_map.files import write_text_atomic

LION_TAGS = [0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 13, 14, 15, 16]


def main() -> None:
    zoo = Path(__file__).resolve().parent.parent / "worlds" / "zoo"
    tags = {t["id"]: t for t in json.loads((zoo / "tags.json").read_text())["tags"]}
    world = json.loads((zoo / "world.json").read_text())
    start = world["start"]
    scenario = {
        "hierarchy": world["hierarchy"],
        "start": [start["x_m"], start["y_m"], start["heading_deg"]],
        "goal": "Lion",
        "steps": [{"text": tags[i]["text"], "tag": i,
                   "pose": [tags[i]["x_m"], tags[i]["y_m"], tags[i]["theta_deg"]]} for i in LION_TAGS],
    }
    write_text_atomic(zoo / "lion_replay.json", json.dumps(scenario, indent=1) + "\n")
    print(f"wrote {zoo / 'lion_replay.json'}")


if __name__ == "__main__":
    main()
