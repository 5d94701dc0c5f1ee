"""Convert the QUT zoo data in ``../shared/zoo`` into the world folder ``worlds/zoo``.

Usage: ``python scripts/convert_zoo.py [SOURCE_DIR] [DEST_DIR]``. Copies the floor
plan, hierarchy and licence, and merges ``tags.txt`` with ``cue_mapping.xml``
into ``tags.json``. The cue mapping's two-character ``\\n`` separators become
real newlines.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from defusedxml import ElementTree

from abstract_map.files import write_bytes_atomic, write_text_atomic

KINDS = {"LABEL": "label", "INFO": "sign", "EMPTY": "empty"}
GOALS = {"Kingfisher": 10, "Toilets": 24, "Lion": 17, "Polar bear": 27, "Anaconda": 38}


def convert(source: Path, dest: Path) -> None:
    dest.mkdir(parents=True, exist_ok=True)
    for name in ("floorplan.png", "hierarchy.xml", "LICENSE-QUT.txt"):
        write_bytes_atomic(dest / name, (source / name).read_bytes())
    mapping = ElementTree.parse(source / "cue_mapping.xml").getroot()
    cues = {int(m.get("tag_id")): (KINDS[m.get("type")], m.get("text").replace("\\n", "\n"))
            for m in mapping.iter("mapping")}
    tags = []
    for line in (source / "tags.txt").read_text().splitlines():
        if not line.strip():
            continue
        tag_id, x, y, theta = line.split()
        kind, text = cues[int(tag_id)]
        tags.append({"id": int(tag_id), "x_m": round(float(x), 4), "y_m": round(float(y), 4),
                     "theta_deg": round(float(theta), 3), "kind": kind, "text": text})
    write_text_atomic(dest / "tags.json", json.dumps({"name": mapping.get("name"), "tags": tags}, indent=1) + "\n")
    world = {
        "format": "abstract-map-world/1",
        "name": "zoo",
        "title": "S11 Zoo (Talbot et al. 2020)",
        "floorplan": {"image": "floorplan.png", "resolution_m": 0.021008,
                      "origin_m": [-29.432773, -18.067227], "occupied_thresh": 0.6,
                      "free_thresh": 0.3, "negate": False},
        "tags": "tags.json",
        "hierarchy": "hierarchy.xml",
        "start": {"x_m": 0.2, "y_m": -11.0, "heading_deg": 90.0},
        "goals": GOALS,
        "tag": {"size_m": 0.25, "height_m": 1.1},
        "walls": {"height_m": 2.0},
        "licence": "LICENSE-QUT.txt",
    }
    write_text_atomic(dest / "world.json", json.dumps(world, indent=2) + "\n")


if __name__ == "__main__":
    here = Path(__file__).resolve().parent.parent
    src = Path(sys.argv[1]) if len(sys.argv) > 1 else here.parent / "shared" / "zoo"
    dst = Path(sys.argv[2]) if len(sys.argv) > 2 else here / "worlds" / "zoo"
    convert(src, dst)
    print(f"wrote {dst}")
