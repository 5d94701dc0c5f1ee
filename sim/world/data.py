"""World folders as data: metadata, floor plan, tags with their cue text, start, goals.

A world is a folder holding ``world.json`` (see ``worlds/README.md``). Loading
it gives a :class:`World`, a plain value with no simulator attached. Frames:
world frame, metres, angles in radians counter-clockwise from +x.
"""

from __future__ import annotations

import difflib
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

FORMAT = "abstract-map-world/1"
TAG_KINDS = ("label", "sign", "empty")

_WORLD_KEYS = {
    "format", "name", "title", "floorplan", "tags", "hierarchy", "start",
    "goals", "tag", "walls", "licence", "oracle_m", "generator",
}
_FLOORPLAN_KEYS = {"image", "resolution_m", "origin_m", "occupied_thresh", "free_thresh", "negate"}
_TAG_KEYS = {"id", "x_m", "y_m", "theta_deg", "kind", "text"}


class WorldError(ValueError):
    """A world folder or one of its files is malformed."""


def _check_keys(where: str, data: dict[str, Any], allowed: set[str], required: set[str]) -> None:
    for key in data:
        if key not in allowed:
            hint = difflib.get_close_matches(key, sorted(allowed), n=1)
            suggestion = f" (did you mean {hint[0]!r}?)" if hint else ""
            raise WorldError(f"{where}: unknown key {key!r}{suggestion}; expected one of {sorted(allowed)}")
    missing = required - set(data)
    if missing:
        raise WorldError(f"{where}: missing key(s) {sorted(missing)}")


def _finite(where: str, *values: float) -> None:
    if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in values):
        raise WorldError(f"{where}: expected finite numbers, got {values!r}")


@dataclass(frozen=True)
class Tag:
    """A tag on a wall: pose of its face (theta is the outward normal) and what it says."""

    id: int
    x: float  # m, world frame
    y: float  # m, world frame
    theta: float  # rad, direction the tag's face points
    kind: str  # "label" (marks a place behind it), "sign" (cue text) or "empty"
    text: str  # lines separated by "\n"

    def to_dict(self) -> dict[str, Any]:
        return {"id": self.id, "x_m": self.x, "y_m": self.y,
                "theta_deg": math.degrees(self.theta), "kind": self.kind, "text": self.text}


@dataclass(frozen=True)
class Floorplan:
    """Occupancy image in map_server convention.

    ``occupied[r, c]`` is True for an obstacle; row 0 is the top of the image.
    ``origin`` is the world position (m) of the bottom-left corner of the image.
    """

    occupied: np.ndarray
    resolution: float  # m per pixel
    origin: tuple[float, float]  # m

    @property
    def shape(self) -> tuple[int, int]:
        return self.occupied.shape  # type: ignore[return-value]

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max) in metres, for matplotlib's imshow."""
        rows, cols = self.occupied.shape
        x0, y0 = self.origin
        return (x0, x0 + cols * self.resolution, y0, y0 + rows * self.resolution)

    def world_to_pixel(self, xy: np.ndarray) -> np.ndarray:
        """World points (N, 2) in metres to integer (row, col) pixel indices (N, 2)."""
        xy = np.atleast_2d(np.asarray(xy, dtype=float))
        rows = self.occupied.shape[0]
        col = np.floor((xy[:, 0] - self.origin[0]) / self.resolution).astype(int)
        row = rows - 1 - np.floor((xy[:, 1] - self.origin[1]) / self.resolution).astype(int)
        return np.stack([row, col], axis=1)

    def pixel_to_world(self, rc: np.ndarray) -> np.ndarray:
        """Pixel (row, col) indices (N, 2) to the world positions (m) of their centres."""
        rc = np.atleast_2d(np.asarray(rc, dtype=float))
        rows = self.occupied.shape[0]
        x = self.origin[0] + (rc[:, 1] + 0.5) * self.resolution
        y = self.origin[1] + (rows - 1 - rc[:, 0] + 0.5) * self.resolution
        return np.stack([x, y], axis=1)


@dataclass(frozen=True)
class World:
    """Everything a trial needs to know about a building."""

    name: str
    root: Path
    title: str
    floorplan: Floorplan
    tags: dict[int, Tag]
    hierarchy_path: Path
    start: tuple[float, float, float]  # x m, y m, heading rad
    goals: dict[str, int]  # goal place -> id of its label tag
    tag_size: float = 0.25  # m, edge of the tag's black square
    tag_height: float = 1.1  # m, height of the tag's centre
    wall_height: float = 2.0  # m
    licence: str | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    oracle_m: dict[str, float] | None = None  # m, per goal: the oracle's path length from the start, if stored
    generator: dict[str, Any] | None = None  # how a generated world was made (seed, style, ...), see worlds/README.md

    def label_tags(self, place: str) -> list[Tag]:
        """The label tags that mark ``place``."""
        return [t for t in self.tags.values() if t.kind == "label" and t.text == place]


def _load_floorplan(root: Path, spec: dict[str, Any]) -> Floorplan:
    from PIL import Image  # pillow ships with matplotlib

    _check_keys("world.json floorplan", spec, _FLOORPLAN_KEYS, {"image", "resolution_m", "origin_m"})
    path = root / spec["image"]
    if not path.is_file():
        raise WorldError(f"{path}: floor plan image not found")
    grey = np.asarray(Image.open(path).convert("L"), dtype=float)
    occupancy = (255.0 - grey) / 255.0
    if spec.get("negate", False):
        occupancy = 1.0 - occupancy
    resolution = float(spec["resolution_m"])
    origin = spec["origin_m"]
    _finite("world.json floorplan", resolution, *origin[:2])
    if resolution <= 0:
        raise WorldError(f"world.json floorplan: resolution_m must be > 0, got {resolution}")
    occupied = occupancy > float(spec.get("occupied_thresh", 0.65))
    return Floorplan(occupied=occupied, resolution=resolution, origin=(float(origin[0]), float(origin[1])))


def _load_tags(path: Path) -> dict[int, Tag]:
    try:
        data = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise WorldError(f"{path}: cannot read tags ({exc})") from exc
    tags: dict[int, Tag] = {}
    for i, entry in enumerate(data.get("tags", [])):
        where = f"{path} tag #{i}"
        _check_keys(where, entry, _TAG_KEYS, _TAG_KEYS)
        _finite(where, entry["x_m"], entry["y_m"], entry["theta_deg"])
        if entry["kind"] not in TAG_KINDS:
            raise WorldError(f"{where}: kind {entry['kind']!r} is not one of {TAG_KINDS}")
        tag = Tag(int(entry["id"]), float(entry["x_m"]), float(entry["y_m"]),
                  math.radians(entry["theta_deg"]), entry["kind"], str(entry["text"]))
        if tag.id in tags:
            raise WorldError(f"{where}: duplicate tag id {tag.id}")
        tags[tag.id] = tag
    return tags


def _load_oracle(spec: Any, goals: dict[str, int]) -> dict[str, float] | None:
    if spec is None:
        return None
    if not isinstance(spec, dict):
        raise WorldError(f"world.json oracle_m: expected a mapping goal -> metres, got {spec!r}")
    for goal, length in spec.items():
        if goal not in goals:
            raise WorldError(f"world.json oracle_m: {goal!r} is not a goal; goals are {sorted(goals)}")
        _finite(f"world.json oracle_m {goal!r}", length)
    return {str(k): float(v) for k, v in spec.items()}


def worlds_dir() -> Path:
    """Where named worlds live: $ABSTRACT_MAP_WORLDS, ./worlds, or the repo's worlds/."""
    env = os.environ.get("ABSTRACT_MAP_WORLDS")
    if env:
        return Path(env)
    local = Path.cwd() / "worlds"
    if local.is_dir():
        return local
    return Path(__file__).resolve().parents[2] / "worlds"


def resolve_world(name_or_path: str | os.PathLike[str]) -> Path:
    """A world folder from a path or a name under :func:`worlds_dir`."""
    path = Path(name_or_path)
    if (path / "world.json").is_file():
        return path
    named = worlds_dir() / str(name_or_path)
    if (named / "world.json").is_file():
        return named
    known = sorted(p.name for p in worlds_dir().glob("*/world.json") for p in [p.parent])
    raise WorldError(f"world {str(name_or_path)!r}: no world.json there nor in {worlds_dir()}; known worlds: {known}")


def load_world(name_or_path: str | os.PathLike[str]) -> World:
    """Load a world folder (or a world by name) into a :class:`World`."""
    root = resolve_world(name_or_path)
    try:
        meta = json.loads((root / "world.json").read_text())
    except json.JSONDecodeError as exc:
        raise WorldError(f"{root / 'world.json'}: not valid JSON ({exc})") from exc
    _check_keys(f"{root / 'world.json'}", meta, _WORLD_KEYS,
                {"format", "name", "floorplan", "tags", "hierarchy", "start", "goals"})
    if meta["format"] != FORMAT:
        raise WorldError(f"{root / 'world.json'}: format {meta['format']!r}, expected {FORMAT!r}")
    start = meta["start"]
    _finite("world.json start", start["x_m"], start["y_m"], start["heading_deg"])
    tags = _load_tags(root / meta["tags"])
    goals = {str(k): int(v) for k, v in meta["goals"].items()}
    for goal, tag_id in goals.items():
        if tag_id not in tags or tags[tag_id].kind != "label" or tags[tag_id].text != goal:
            raise WorldError(f"world.json goals: {goal!r} names tag {tag_id}, which is not a label for {goal!r}")
    hierarchy_path = root / meta["hierarchy"]
    if not hierarchy_path.is_file():
        raise WorldError(f"{hierarchy_path}: hierarchy file not found")
    tag_spec = meta.get("tag", {})
    return World(
        name=meta["name"],
        root=root,
        title=meta.get("title", meta["name"]),
        floorplan=_load_floorplan(root, meta["floorplan"]),
        tags=tags,
        hierarchy_path=hierarchy_path,
        start=(float(start["x_m"]), float(start["y_m"]), math.radians(start["heading_deg"])),
        goals=goals,
        tag_size=float(tag_spec.get("size_m", 0.25)),
        tag_height=float(tag_spec.get("height_m", 1.1)),
        wall_height=float(meta.get("walls", {}).get("height_m", 2.0)),
        licence=meta.get("licence"),
        oracle_m=_load_oracle(meta.get("oracle_m"), goals),
        generator=meta.get("generator"),
    )
