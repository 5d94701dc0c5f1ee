"""Save and load an abstract map as versioned JSON.

The file holds the model's state, not its pymunk space: the hierarchy, the
fixed points, the clauses of every cue, each place's position and velocity,
the exploration factor, the explored centre and the parameters. Floats are
written with full precision, so a round trip gives identical positions and
the loaded model settles exactly as the saved one would.
"""

from __future__ import annotations

import json
import logging
import os
from dataclasses import asdict, fields
from pathlib import Path
from typing import Any

import numpy as np

from . import errors
from .clauses import START_ANCHOR, Clause, Locational, Relational, is_anchor
from .errors import AbstractMapError, ModelFileError
from .files import write_text_atomic
from .hierarchy import Hierarchy
from .model import FIXED_KINDS, AbstractMap, FixedPoint
from .params import AbstractMapParams, DynamicsParams, ExplorationParams, ScaleDefaults

__all__ = ["FORMAT", "ModelFileError", "from_dict", "load", "save", "to_dict"]

log = logging.getLogger(__name__)

FORMAT = "abstract-map/1"
_KEYS = ("format", "params", "hierarchy", "start", "start_roots", "goal", "fixed", "cue_clauses",
         "loose_clauses", "positions", "velocities", "exploration_factor", "explored_centre", "settled_moving")
# "settled_moving": null, or the places left moving when the model is saved just as its last settle left it
_FIXED_KEYS = ("kind", "x", "y", "theta", "sightings", "text")
# dynamics parameters older files lack (they load with the defaults)
_NEW_DYNAMICS = ("angle_length", "angle_core_share", "wake_acceleration", "solver_iterations", "angle_core_wdt")
# dynamics parameters older files have that no longer exist, and what replaced them
_RETIRED_DYNAMICS = {"angle_law": "angle springs follow the potential law, the force of K l error^2 / 2"}


def params_to_dict(params: AbstractMapParams) -> dict[str, Any]:
    data = asdict(params)
    data["scales"]["place"] = {f"{a}-{b}": v for (a, b), v in params.scales.place.items()}
    data["scales"]["sign"] = {str(k): v for k, v in params.scales.sign.items()}
    data["scales"]["label"] = {str(k): v for k, v in params.scales.label.items()}
    return data


def _object(where: str, data: Any, keys: tuple[str, ...] | None = None, *, optional: tuple[str, ...] = ()) -> dict:
    """``data`` if it is a JSON object with exactly ``keys`` (``optional`` ones may be absent)."""
    if not isinstance(data, dict):
        raise ModelFileError(f"{where}: expected an object, got {errors.show(data)}")
    if keys is not None:
        unknown = [k for k in data if k not in keys]
        missing = [k for k in keys if k not in data and k not in optional]
        if unknown or missing:
            raise ModelFileError(f"{where}: unknown key(s) {unknown[:5]}, missing key(s) {missing[:5]}; "
                                 f"expected {list(keys)}")
    return data


def _list(where: str, data: Any, length: int | None = None) -> list:
    if not isinstance(data, list) or (length is not None and len(data) != length):
        raise ModelFileError(f"{where}: expected a list{'' if length is None else f' of {length}'}, "
                             f"got {errors.show(data)}")
    return data


def _level(where: str, text: Any) -> int:
    if not isinstance(text, str) or not text.isdigit() or len(text) > 3:
        raise ModelFileError(f"{where}: expected a level such as '1', got {errors.show(text)}")
    return int(text)


def _table(where: str, data: Any) -> dict[int, float]:
    return {_level(f"{where} level", k): errors.number(f"{where}[{k}]", v, error=ModelFileError)
            for k, v in _object(where, data).items()}


def params_from_dict(data: Any, *, where: str = "params") -> AbstractMapParams:
    """Inverse of :func:`params_to_dict`; every value checked."""
    names = tuple(f.name for f in fields(AbstractMapParams))
    data = _object(where, data, names, optional=("loose_stiffness",))
    scales = _object(f"{where} scales", data["scales"], ("place", "sign", "label"))
    place = {}
    for key, value in _object(f"{where} scales place", scales["place"]).items():
        parts = key.split("-") if isinstance(key, str) else []
        if len(parts) != 2:
            raise ModelFileError(f"{where} scales place: expected a level pair such as '1-2', got {key!r}")
        place[(_level(f"{where} scales place", parts[0]), _level(f"{where} scales place", parts[1]))] = \
            errors.number(f"{where} scales place[{key}]", value, error=ModelFileError)
    dynamics = dict(_object(f"{where} dynamics", data["dynamics"],
                            (*(f.name for f in fields(DynamicsParams)), *_RETIRED_DYNAMICS),
                            optional=(*_NEW_DYNAMICS, *_RETIRED_DYNAMICS)))
    for key, meaning in _RETIRED_DYNAMICS.items():
        if key in dynamics:
            log.warning("%s dynamics: %s=%s is no longer a parameter (%s)", where, key,
                        errors.show(dynamics.pop(key)), meaning)
    exploration = _object(f"{where} exploration", data["exploration"],
                          tuple(f.name for f in fields(ExplorationParams)), optional=("max_factor",))
    try:
        return AbstractMapParams(
            scales=ScaleDefaults(place=place, sign=_table(f"{where} scales sign", scales["sign"]),  # type: ignore[arg-type]
                                 label=_table(f"{where} scales label", scales["label"])),
            dynamics=DynamicsParams(**dynamics),
            exploration=ExplorationParams(**exploration),
            **{k: data[k] for k in names if k not in ("scales", "dynamics", "exploration") and k in data},
        )
    except (TypeError, ValueError) as exc:
        raise ModelFileError(f"{where}: {exc}") from None


def to_dict(model: AbstractMap) -> dict[str, Any]:
    """The model as plain JSON-able data."""
    return {
        "format": FORMAT,
        "params": params_to_dict(model.params),
        "hierarchy": {"places": list(model.hierarchy.places),
                      "parent": [[c, p] for c, p in model.hierarchy.parent.items()]},
        "start": list(model.start),
        "start_roots": list(model.start_roots),
        "goal": model.goal,
        "fixed": {name: {"kind": f.kind, "x": f.x, "y": f.y, "theta": f.theta,
                         "sightings": f.sightings, "text": f.text} for name, f in model.fixed.items()},
        "cue_clauses": {name: [c.to_dict() for c in cs] for name, cs in model.cue_clauses.items()},
        "loose_clauses": [c.to_dict() for c in model.loose_clauses],
        "positions": {n: [float(v) for v in xy] for n, xy in model.positions.items()},
        "velocities": {n: [float(v) for v in xy] for n, xy in model.velocities.items()},
        "exploration_factor": model.exploration_factor,
        "explored_centre": None if model.explored_centre is None else [float(v) for v in model.explored_centre],
        "settled_moving": model.as_last_settled(),
    }


def _name(where: str, name: Any, *, anchors: bool = False) -> str:
    if anchors and isinstance(name, str) and is_anchor(name):
        if name != START_ANCHOR and not (name[1:].isdigit() and len(name) <= 12):
            raise ModelFileError(f"{where}: fixed point {errors.show(name)} is not '#start' or '#<tag id>'")
        return name
    return errors.place_name(where, name, error=ModelFileError)


def _clause(where: str, data: Any) -> Clause:
    data = _object(where, data)
    if data.get("type") == "relational":
        data = _object(where, data, ("type", "preposition", "figure", "referents", "context"))
        if not isinstance(data["preposition"], str):
            raise ModelFileError(f"{where}: preposition must be text, got {errors.show(data['preposition'])}")
        context = data["context"]
        return Relational(data["preposition"], _name(f"{where} figure", data["figure"], anchors=True),
                          tuple(_name(f"{where} referent", r, anchors=True)
                                for r in _list(f"{where} referents", data["referents"])),
                          None if context is None else _name(f"{where} context", context, anchors=True))
    if data.get("type") == "locational":
        data = _object(where, data, ("type", "kind", "toponym", "anchor", "direction"))
        if not isinstance(data["kind"], str) or not isinstance(data["anchor"], str):
            raise ModelFileError(f"{where}: kind and anchor must be text")
        return Locational(data["kind"], _name(f"{where} toponym", data["toponym"]), data["anchor"],
                          errors.number(f"{where} direction", data["direction"], low=-4.0, high=4.0,
                                        error=ModelFileError))
    raise ModelFileError(f"{where}: expected 'type' to be 'relational' or 'locational', got {errors.show(data)}")


def _fixed(where: str, name: str, data: Any) -> FixedPoint:
    data = _object(where, data, _FIXED_KEYS)
    kind = data["kind"]
    if kind not in FIXED_KINDS or (kind == "start") != (name == START_ANCHOR):
        raise ModelFileError(f"{where}: kind {errors.show(kind)}; expected 'start' for '#start', "
                             "else 'label' or 'sign'")
    if not isinstance(data["text"], str):
        raise ModelFileError(f"{where}: text must be a string, got {errors.show(data['text'])}")
    x, y, theta = errors.pose(where, [data["x"], data["y"], data["theta"]], error=ModelFileError)
    sightings = errors.integer(f"{where} sightings", data["sightings"], low=1, high=2**53, error=ModelFileError)
    return FixedPoint(kind, x, y, theta, sightings, data["text"])


def _xy(where: str, data: Any, limit: float) -> np.ndarray:
    values = _list(where, data, 2)
    return np.array([errors.number(f"{where} {axis}", v, low=-limit, high=limit, error=ModelFileError)
                     for axis, v in zip("xy", values)])


def from_dict(data: Any, *, where: str = "model") -> AbstractMap:
    """Inverse of :func:`to_dict`: every field is checked, or :class:`ModelFileError` names it."""
    data = _object(where, data)
    if data.get("format") != FORMAT:
        raise ModelFileError(f"{where}: format {errors.show(data.get('format'))}, expected {FORMAT!r}")
    data = _object(where, data, _KEYS, optional=("settled_moving",))  # files from before island settles lack it
    params = params_from_dict(data["params"], where=f"{where} params")
    spec = _object(f"{where} hierarchy", data["hierarchy"], ("places", "parent"))
    try:
        hierarchy = Hierarchy()
        for name in _list(f"{where} hierarchy places", spec["places"]):
            if _name(f"{where} hierarchy places", name) in hierarchy:
                raise ModelFileError(f"{where} hierarchy places: {errors.show(name)} is listed twice")
            hierarchy.add_place(_name(f"{where} hierarchy places", name), where=f"{where} hierarchy")
        for pair in _list(f"{where} hierarchy parent", spec["parent"]):
            child, parent = (_name(f"{where} hierarchy parent", n) for n in _list(f"{where} hierarchy parent", pair, 2))
            if child not in hierarchy or parent not in hierarchy:
                raise ModelFileError(f"{where} hierarchy parent: {errors.show(pair)} names a place not listed")
            hierarchy.add(child, parent, where=f"{where} hierarchy")
    except AbstractMapError as exc:
        raise ModelFileError(str(exc)) from None
    start = errors.pose(f"{where} start", data["start"], error=ModelFileError)
    fixed = {_name(f"{where} fixed", n, anchors=True): _fixed(f"{where} fixed {n}", n, f)
             for n, f in _object(f"{where} fixed", data["fixed"]).items()}
    if START_ANCHOR not in fixed:
        raise ModelFileError(f"{where} fixed: no '#start'")
    if (fixed[START_ANCHOR].x, fixed[START_ANCHOR].y, fixed[START_ANCHOR].theta) != start:
        raise ModelFileError(f"{where} fixed: '#start' is not at the start pose")
    cue_clauses = {}
    for name, clauses in _object(f"{where} cue_clauses", data["cue_clauses"]).items():
        if name not in fixed or name == START_ANCHOR:
            raise ModelFileError(f"{where} cue_clauses: {errors.show(name)} is not an observed tag")
        cue_clauses[name] = [_clause(f"{where} cue_clauses {name}[{i}]", c)
                             for i, c in enumerate(_list(f"{where} cue_clauses {name}", clauses))]
    loose = [_clause(f"{where} loose_clauses[{i}]", c)
             for i, c in enumerate(_list(f"{where} loose_clauses", data["loose_clauses"]))]
    roots = [_name(f"{where} start_roots", r) for r in _list(f"{where} start_roots", data["start_roots"])]
    if any(r not in hierarchy for r in roots) or len(set(roots)) != len(roots):
        raise ModelFileError(f"{where} start_roots: {errors.show(roots)} must be distinct hierarchy places")
    limit = params.exploration.max_factor
    exploration = errors.number(f"{where} exploration_factor", data["exploration_factor"], low=1.0, high=limit,
                                error=ModelFileError)
    centre = data["explored_centre"]
    goal = data["goal"]
    try:
        model = AbstractMap(hierarchy=hierarchy, start=start, params=params, goal=None, fixed=fixed,
                            start_roots=roots, exploration_factor=exploration,
                            explored_centre=None if centre is None else _xy(f"{where} explored_centre", centre,
                                                                            errors.COORDINATE_LIMIT_M))
        for clause in [c for cs in cue_clauses.values() for c in cs] + loose:
            model.check_clause(clause, fixed)
        model.cue_clauses, model.loose_clauses = cue_clauses, loose
        places = set(model.places())
        for key, limit_value in (("positions", errors.COORDINATE_LIMIT_M), ("velocities", errors.VELOCITY_LIMIT_M_S)):
            values = {}
            for n, xy in _object(f"{where} {key}", data[key]).items():
                if n not in places:
                    raise ModelFileError(f"{where} {key}: {errors.show(n)} is not a place of the model")
                values[n] = _xy(f"{where} {key} {n}", xy, limit_value)
            setattr(model, key, values)
        if not set(model.velocities) <= set(model.positions):
            raise ModelFileError(f"{where} velocities: a place has a velocity but no position")
        if goal is not None:
            model.set_goal(goal)
            if model.goal != goal:
                raise ModelFileError(f"{where} goal: {errors.show(goal)} is not a place's spelling")
        model.springs()
        model.levels()
        moving = data.get("settled_moving")
        if moving is not None:
            moving = [_name(f"{where} settled_moving", n) for n in _list(f"{where} settled_moving", moving)]
            unknown = [n for n in moving if n not in model.positions]
            if unknown:
                raise ModelFileError(f"{where} settled_moving: {errors.show(unknown[0])} is not a placed place")
            if not set(model.places()) <= set(model.positions):
                raise ModelFileError(f"{where} settled_moving: given, but some places have no position")
            model.resume_settled(moving)
    except ModelFileError:
        raise
    except (AbstractMapError, ValueError) as exc:
        raise ModelFileError(f"{where}: {exc}") from None
    return model


def save(model: AbstractMap, path: str | os.PathLike[str]) -> None:
    """Write the model to a JSON file (atomically: a failed save leaves any earlier file intact)."""
    write_text_atomic(path, json.dumps(to_dict(model), indent=1, allow_nan=False))


def load(path: str | os.PathLike[str]) -> AbstractMap:
    """Read a model written by :func:`save`; anything else raises :class:`ModelFileError` naming it."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as exc:
        raise ModelFileError(f"{path}: cannot read model ({exc.strerror or exc})") from exc
    except (ValueError, RecursionError) as exc:  # JSONDecodeError and UnicodeDecodeError are ValueErrors
        raise ModelFileError(f"{path}: not a model file ({errors.one_line(str(exc), 120)})") from None
    return from_dict(data, where=str(path))
