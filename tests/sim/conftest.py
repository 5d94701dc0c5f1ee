"""A tiny synthetic building for the simulator tests.

A 10 m x 8 m floor plan at 0.05 m/px, origin (0, 0): an outer wall 0.2 m thick
and an inner wall at x = 6.0 .. 6.2 m from y = 0 up to y = 5 m (the room's
east part is reached around its end). Tags (id: pose, kind):

* 0: (6.0, 2.5) facing -x, on the inner wall's west face, label "A"
* 1: (3.0, 6.0) facing +y, free-standing sign
* 2: (7.5, 2.5) facing -x, free-standing, east of the inner wall
* 3: (6.2, 1.0) facing +x, on the inner wall's east face, empty
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pybullet")

from sim.world.data import World, load_world  # noqa: E402

RESOLUTION = 0.05  # m/px
SIZE = (10.0, 8.0)  # m, x by y
INNER_WALL_X = (6.0, 6.2)  # m
INNER_WALL_TOP = 5.0  # m
OUTER_WALL = 0.2  # m
TAGS = [
    {"id": 0, "x_m": 6.0, "y_m": 2.5, "theta_deg": 180.0, "kind": "label", "text": "A"},
    {"id": 1, "x_m": 3.0, "y_m": 6.0, "theta_deg": 90.0, "kind": "sign", "text": "$UP$ A"},
    {"id": 2, "x_m": 7.5, "y_m": 2.5, "theta_deg": 180.0, "kind": "sign", "text": "$LEFT$ A"},
    {"id": 3, "x_m": 6.2, "y_m": 1.0, "theta_deg": 0.0, "kind": "empty", "text": ""},
]


def _floorplan() -> np.ndarray:
    """Grey image (rows, cols) uint8, row 0 at the top (y = 8 m): 0 = wall, 255 = free."""
    cols, rows = round(SIZE[0] / RESOLUTION), round(SIZE[1] / RESOLUTION)
    image = np.full((rows, cols), 255, dtype=np.uint8)
    edge = round(OUTER_WALL / RESOLUTION)
    image[:edge, :] = image[-edge:, :] = image[:, :edge] = image[:, -edge:] = 0
    c0, c1 = (round(x / RESOLUTION) for x in INNER_WALL_X)
    top_row = rows - round(INNER_WALL_TOP / RESOLUTION)
    image[top_row:, c0:c1] = 0
    return image


def write_world(root: Path) -> Path:
    """Write the tiny world folder under ``root`` and return it."""
    from PIL import Image

    root.mkdir(parents=True, exist_ok=True)
    Image.fromarray(_floorplan()).save(root / "floorplan.png")
    (root / "tags.json").write_text(json.dumps({"name": "tiny", "tags": TAGS}, indent=1))
    (root / "hierarchy.xml").write_text('<hierarchy><place name="Campus"><place name="A"/></place></hierarchy>\n')
    meta = {
        "format": "abstract-map-world/1",
        "name": "tiny",
        "title": "Tiny test building",
        "floorplan": {"image": "floorplan.png", "resolution_m": RESOLUTION, "origin_m": [0.0, 0.0],
                      "occupied_thresh": 0.65, "free_thresh": 0.2, "negate": False},
        "tags": "tags.json",
        "hierarchy": "hierarchy.xml",
        "start": {"x_m": 2.0, "y_m": 2.0, "heading_deg": 0.0},
        "goals": {"A": 0},
        "tag": {"size_m": 0.25, "height_m": 1.1},
        "walls": {"height_m": 2.0},
    }
    (root / "world.json").write_text(json.dumps(meta, indent=2))
    return root


@pytest.fixture(scope="session")
def tiny_world(tmp_path_factory: pytest.TempPathFactory) -> World:
    """The tiny world, loaded with :func:`sim.world.data.load_world`."""
    return load_world(write_world(tmp_path_factory.mktemp("worlds") / "tiny"))


@pytest.fixture(scope="module")
def tiny_scene(tiny_world: World):
    """The tiny world built in its own pybullet client, shared by a test module."""
    from sim.world.scene import build_scene

    scene = build_scene(tiny_world)
    yield scene
    scene.close()


@pytest.fixture(scope="session")
def tiny_world_writer():
    """:func:`write_world`, for tests that write (and then break) their own copy of the tiny world."""
    return write_world
