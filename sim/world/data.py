"""World folders as data: metadata, floor plan, tags with their cue text, start, goals.

A world is a folder holding ``world.json`` (see ``worlds/README.md``). Loading
it gives a :class:`World`, a plain value with no simulator attached. Frames:
world frame, metres, angles in radians counter-clockwise from +x.

Loading validates the whole folder before returning: the schema of every file,
every number's range, the floor plan image, the hierarchy, every tag's text
(read by the abstract map exactly as a trial would read it) and every goal.
A malformed world raises one :class:`WorldError` listing every problem found.
"""

from __future__ import annotations

import difflib
import json
import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from abstract_map import errors
from abstract_map.clauses import Clause, tag_anchor
from abstract_map.errors import AbstractMapError, one_line
from abstract_map.grammar import Anchor, parse_cue
from abstract_map.hierarchy import Hierarchy

FORMAT = "abstract-map-world/1"
TAG_KINDS = ("label", "sign", "empty")

_WORLD_KEYS = {
    "format", "name", "title", "floorplan", "tags", "hierarchy", "start",
    "goals", "tag", "walls", "licence", "oracle_m", "generator",
}
_FLOORPLAN_KEYS = {"image", "resolution_m", "origin_m", "occupied_thresh", "free_thresh", "negate"}
_TAG_KEYS = {"id", "x_m", "y_m", "theta_deg", "kind", "text"}


TAG_FAMILY_SIZE = 587
"""Ids of the AprilTag 36h11 family, whose real images the scene renders: 0 to 586."""
MIN_FLOORPLAN_PX = 8
"""A floor plan has at least this many pixels each way (a 1x1 plan has no inside)."""
MAX_FLOORPLAN_PX = 20_000
"""... and at most this many each way (400 Mpx; the zoo's is 2,855 x 1,666)."""


class WorldError(AbstractMapError):
    """A world folder or one of its files is malformed; the message lists every problem found."""


class _Problems:
    """Problems found while loading, reported together."""

    def __init__(self) -> None:
        self.found: list[str] = []

    def add(self, message: str) -> None:
        self.found.append(one_line(message, 300))

    def guard(self, fn: Callable[[], Any]) -> Any:
        """``fn()``, or None with its :class:`AbstractMapError` recorded."""
        try:
            return fn()
        except AbstractMapError as exc:
            self.add(str(exc))
            return None

    def raise_if_any(self, where: Path) -> None:
        if self.found:
            shown = self.found[:20] + ([f"and {len(self.found) - 20} more"] if len(self.found) > 20 else [])
            raise WorldError(f"{where}: {len(self.found)} problem(s): " + "; ".join(shown))


def _check_keys(where: str, data: Any, allowed: set[str], required: set[str]) -> None:
    if not isinstance(data, dict):
        raise WorldError(f"{where}: expected an object, got {errors.show(data)}")
    for key in data:
        if key not in allowed:
            hint = difflib.get_close_matches(str(key), sorted(allowed), n=1)
            suggestion = f" (did you mean {hint[0]!r}?)" if hint else ""
            raise WorldError(f"{where}: unknown key {errors.show(key)}{suggestion}; expected one of {sorted(allowed)}")
    missing = required - set(data)
    if missing:
        raise WorldError(f"{where}: missing key(s) {sorted(missing)}")


def _number(where: str, value: Any, low: float, high: float) -> float:
    return errors.number(where, value, low=low, high=high, error=WorldError)


def _file(root: Path, where: str, name: Any) -> Path:
    """A file named inside the world folder (no absolute paths, no '..')."""
    if not isinstance(name, str) or not name.strip() or "\x00" in name:
        raise WorldError(f"{where}: expected a file name, got {errors.show(name)}")
    relative = Path(name)
    if relative.is_absolute() or ".." in relative.parts:
        raise WorldError(f"{where}: {name!r} must name a file inside the world folder")
    path = root / relative
    if not path.is_file():
        raise WorldError(f"{where}: {path} not found")
    return path


def _json(path: Path) -> Any:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise WorldError(f"{path}: cannot read ({exc.strerror or exc})") from None
    except (ValueError, RecursionError) as exc:  # JSONDecodeError, UnicodeDecodeError
        raise WorldError(f"{path}: not valid JSON ({one_line(str(exc), 120)})") from None


@dataclass(frozen=True)
class Tag:
    """A tag on a wall: pose of its face (theta is the outward normal) and what it says."""

    id: int
    x: float  # m, world frame
    y: float  # m, world frame
    theta: float  # rad, direction the tag's face points
    kind: str  # "label" (marks a place behind it), "sign" (cue text) or "empty"
    text: str  # lines separated by "\n"

    def clauses(self) -> list[Clause]:
        """What the tag says as clauses of the grammar, anchored at its own pose (anchor ``#<id>``); raises
        :class:`abstract_map.grammar.CueError` for text the grammar does not read."""
        return parse_cue(self.text, Anchor(tag_anchor(self.id), self.x, self.y, self.theta), kind=self.kind)

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

    def wall_at(self, xy: np.ndarray) -> np.ndarray:
        """Per world point (N, 2, m): whether it falls on an obstacle pixel; outside the image counts as wall."""
        rc = self.world_to_pixel(xy)
        rows, cols = self.occupied.shape
        inside = (rc[:, 0] >= 0) & (rc[:, 0] < rows) & (rc[:, 1] >= 0) & (rc[:, 1] < cols)
        out = np.ones(len(rc), dtype=bool)
        out[inside] = self.occupied[rc[inside, 0], rc[inside, 1]]
        return out

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


def _load_floorplan(root: Path, spec: Any) -> Floorplan:
    from PIL import Image  # pillow ships with matplotlib

    where = "world.json floorplan"
    _check_keys(where, spec, _FLOORPLAN_KEYS, {"image", "resolution_m", "origin_m"})
    problems = _Problems()
    resolution = problems.guard(lambda: _number(f"{where} resolution_m", spec["resolution_m"], 1e-4, 10.0))
    origin = spec["origin_m"]
    if not isinstance(origin, list) or len(origin) != 2:
        problems.add(f"{where} origin_m: expected [x, y] in metres, got {errors.show(origin)}")
        origin = None
    else:
        origin = [problems.guard(lambda v=v, a=a: errors.coordinate(f"{where} origin_m {a}", v, WorldError))
                  for a, v in zip("xy", origin)]
    occupied_thresh = problems.guard(lambda: _number(f"{where} occupied_thresh", spec.get("occupied_thresh", 0.65),
                                                     0.0, 1.0))
    problems.guard(lambda: _number(f"{where} free_thresh", spec.get("free_thresh", 0.2), 0.0, 1.0))
    negate = spec.get("negate", False)
    if not isinstance(negate, bool):
        problems.add(f"{where} negate: expected true or false, got {errors.show(negate)}")
    grey = None
    path = problems.guard(lambda: _file(root, f"{where} image", spec["image"]))
    if path is not None:
        try:
            with Image.open(path) as image:
                width, height = image.size
                if not (MIN_FLOORPLAN_PX <= min(width, height) and max(width, height) <= MAX_FLOORPLAN_PX):
                    problems.add(f"{path}: {width} x {height} pixels; a floor plan has {MIN_FLOORPLAN_PX} to "
                                 f"{MAX_FLOORPLAN_PX} each way")
                else:
                    grey = np.asarray(image.convert("L"), dtype=float)
        except Exception as exc:  # Pillow raises many types for a bad image  # noqa: BLE001
            problems.add(f"{path}: not a readable image ({type(exc).__name__}: {one_line(str(exc), 100)})")
    if problems.found or grey is None or origin is None or None in origin:
        raise WorldError("; ".join(problems.found) or f"{where}: unusable")
    occupancy = (255.0 - grey) / 255.0
    if negate:
        occupancy = 1.0 - occupancy
    return Floorplan(occupied=occupancy > occupied_thresh, resolution=resolution,
                     origin=(float(origin[0]), float(origin[1])))


def _tag(where: str, entry: Any) -> Tag:
    _check_keys(where, entry, _TAG_KEYS, _TAG_KEYS)
    tag_id = errors.integer(f"{where} id", entry["id"], low=0, high=TAG_FAMILY_SIZE, error=WorldError)
    x = errors.coordinate(f"{where} x_m", entry["x_m"], WorldError)
    y = errors.coordinate(f"{where} y_m", entry["y_m"], WorldError)
    theta = errors.angle(f"{where} theta_deg", entry["theta_deg"], WorldError)
    if entry["kind"] not in TAG_KINDS:
        raise WorldError(f"{where}: kind {errors.show(entry['kind'])} is not one of {TAG_KINDS}")
    if not isinstance(entry["text"], str):
        raise WorldError(f"{where}: text must be a string, got {errors.show(entry['text'])}")
    return Tag(tag_id, x, y, math.radians(theta), entry["kind"], entry["text"])


def _load_tags(path: Path, problems: _Problems) -> dict[int, Tag]:
    data = _json(path)
    _check_keys(str(path), data, {"name", "tags"}, {"tags"})
    entries = data["tags"]
    if not isinstance(entries, list) or not entries:
        raise WorldError(f"{path} tags: expected a non-empty list of tags, got {errors.show(entries)}")
    tags: dict[int, Tag] = {}
    for i, entry in enumerate(entries):
        tag = problems.guard(lambda i=i, entry=entry: _tag(f"{path} tag #{i}", entry))
        if tag is None:
            continue
        if tag.id in tags:
            problems.add(f"{path} tag #{i}: duplicate tag id {tag.id}")
        tags[tag.id] = tag
    return tags


def _load_oracle(spec: Any, goals: dict[str, int]) -> dict[str, float] | None:
    if spec is None:
        return None
    if not isinstance(spec, dict):
        raise WorldError(f"world.json oracle_m: expected a mapping goal -> metres, got {spec!r}")
    for goal in spec:
        if goal not in goals:
            raise WorldError(f"world.json oracle_m: {goal!r} is not a goal; goals are {sorted(goals)}")
    return {str(k): _number(f"world.json oracle_m {k!r}", v, 0.0, 1e6) for k, v in spec.items()}


def _read_tags(hierarchy: Hierarchy, start: tuple[float, float, float], tags: dict[int, Tag],
               problems: _Problems) -> None:
    """Every tag's text read by an abstract map as a trial reads it: each must be accepted."""
    from abstract_map.model import AbstractMap

    model = AbstractMap.from_hierarchy(hierarchy, start)
    for tag in tags.values():
        if tag.kind == "empty":
            continue
        try:
            model.observe_tag(tag.id, tag.text, (tag.x, tag.y, tag.theta), kind=tag.kind)
        except AbstractMapError as exc:
            problems.add(f"tag {tag.id} ({tag.kind}): {exc}")


def _inside(floorplan: Floorplan, x: float, y: float, margin: float = 0.0) -> bool:
    x0, x1, y0, y1 = floorplan.extent
    return x0 - margin <= x <= x1 + margin and y0 - margin <= y <= y1 + margin


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
    if not isinstance(name_or_path, (str, os.PathLike)) or not str(name_or_path).strip():
        raise WorldError(f"world: expected a folder or a world's name, got {errors.show(name_or_path)}")
    try:
        path = Path(name_or_path)
        if (path / "world.json").is_file():
            return path
        named = worlds_dir() / str(name_or_path)
        if (named / "world.json").is_file():
            return named
    except (OSError, ValueError) as exc:
        raise WorldError(f"world {errors.show(str(name_or_path), 300)}: {exc}") from None
    known = sorted(p.name for p in worlds_dir().glob("*/world.json") for p in [p.parent])
    raise WorldError(f"world {errors.show(str(name_or_path), 300)}: no world.json there nor in {worlds_dir()}; "
                     f"known worlds: {known}")


def load_world(name_or_path: str | os.PathLike[str]) -> World:
    """Load and validate a world folder (or a world by name) into a :class:`World`.

    Raises one :class:`WorldError` listing every problem found.
    """
    root = resolve_world(name_or_path)
    meta_path = root / "world.json"
    meta = _json(meta_path)
    _check_keys(str(meta_path), meta, _WORLD_KEYS,
                {"format", "name", "floorplan", "tags", "hierarchy", "start", "goals"})
    if meta["format"] != FORMAT:
        raise WorldError(f"{meta_path}: format {errors.show(meta['format'])}, expected {FORMAT!r}")
    problems = _Problems()
    name = problems.guard(lambda: errors.place_name("world.json name", meta["name"], error=WorldError))
    title = meta.get("title", meta["name"])
    if not isinstance(title, str):
        problems.add(f"world.json title: expected text, got {errors.show(title)}")
    floorplan = problems.guard(lambda: _load_floorplan(root, meta["floorplan"]))
    tags_path = problems.guard(lambda: _file(root, "world.json tags", meta["tags"]))
    tags = problems.guard(lambda: _load_tags(tags_path, problems)) if tags_path else None
    hierarchy_path = problems.guard(lambda: _file(root, "world.json hierarchy", meta["hierarchy"]))
    hierarchy = problems.guard(lambda: Hierarchy.from_xml(hierarchy_path)) if hierarchy_path else None
    start = problems.guard(lambda: _start(meta["start"]))
    if start is not None and floorplan is not None:
        row, col = floorplan.world_to_pixel(np.array(start[:2]))[0]
        if not _inside(floorplan, *start[:2]) or floorplan.occupied[row, col]:
            problems.add(f"world.json start: ({start[0]}, {start[1]}) is not on free floor of the plan")
    if tags is not None and floorplan is not None:
        for tag in tags.values():
            if not _inside(floorplan, tag.x, tag.y, margin=1.0):
                problems.add(f"tag {tag.id}: ({tag.x}, {tag.y}) is off the floor plan")
    goals = problems.guard(lambda: _goals(meta["goals"], tags, hierarchy))
    if hierarchy is not None and tags is not None:  # the start only anchors the model: any will do
        _read_tags(hierarchy, start or (0.0, 0.0, 0.0), tags, problems)
    tag_spec = problems.guard(lambda: _optional(meta, "tag", {"size_m": (0.25, 0.01, 2.0),
                                                               "height_m": (1.1, 0.0, 10.0)}))
    walls = problems.guard(lambda: _optional(meta, "walls", {"height_m": (2.0, 0.05, 100.0)}))
    licence = meta.get("licence")
    if licence is not None:
        problems.guard(lambda: _file(root, "world.json licence", licence))
    problems.raise_if_any(root)
    return World(
        name=name,
        root=root,
        title=title,
        floorplan=floorplan,
        tags=tags,
        hierarchy_path=hierarchy_path,
        start=start,
        goals=goals,
        tag_size=tag_spec["size_m"],
        tag_height=tag_spec["height_m"],
        wall_height=walls["height_m"],
        licence=licence,
        oracle_m=_load_oracle(meta.get("oracle_m"), goals),
        generator=meta.get("generator"),
    )


def _start(spec: Any) -> tuple[float, float, float]:
    _check_keys("world.json start", spec, {"x_m", "y_m", "heading_deg"}, {"x_m", "y_m", "heading_deg"})
    x = errors.coordinate("world.json start x_m", spec["x_m"], WorldError)
    y = errors.coordinate("world.json start y_m", spec["y_m"], WorldError)
    heading = errors.angle("world.json start heading_deg", spec["heading_deg"], WorldError)
    return (x, y, math.radians(heading))


def _goals(spec: Any, tags: dict[int, Tag] | None, hierarchy: Hierarchy | None) -> dict[str, int]:
    if not isinstance(spec, dict) or not spec:
        raise WorldError(f"world.json goals: expected a non-empty object of place -> label tag id, "
                         f"got {errors.show(spec)}")
    goals: dict[str, int] = {}
    found: list[str] = []
    for goal, tag_id in spec.items():
        try:
            errors.place_name("world.json goals", goal, error=WorldError)
            tag_id = errors.integer(f"world.json goals {goal!r}", tag_id, low=0, high=TAG_FAMILY_SIZE,
                                    error=WorldError)
        except WorldError as exc:
            found.append(str(exc))
            continue
        if tags is not None and (tag_id not in tags or tags[tag_id].kind != "label" or tags[tag_id].text != goal):
            found.append(f"world.json goals: {goal!r} names tag {tag_id}, which is not a label for {goal!r}")
        if hierarchy is not None and goal not in hierarchy:
            found.append(f"world.json goals: {goal!r} is not a place of the hierarchy")
        goals[goal] = tag_id
    if found:
        raise WorldError("; ".join(found))
    return goals


def _optional(meta: dict[str, Any], key: str, fields: dict[str, tuple[float, float, float]]) -> dict[str, float]:
    """An optional object of numbers: field -> (default, low, high)."""
    spec = meta.get(key, {})
    _check_keys(f"world.json {key}", spec, set(fields), set())
    return {name: _number(f"world.json {key} {name}", spec.get(name, default), low, high)
            for name, (default, low, high) in fields.items()}
