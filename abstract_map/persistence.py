"""Save and load an abstract map as versioned JSON.

The file holds the model's state, not its pymunk space: the hierarchy, the
fixed points, the clauses of every cue, each place's position and velocity,
the exploration factor, the explored centre and the parameters. Floats are
written with full precision, so a round trip gives identical positions and
the loaded model settles exactly as the saved one would.
"""

from __future__ import annotations

import json
import os
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from .clauses import clause_from_dict
from .hierarchy import Hierarchy
from .model import AbstractMap, FixedPoint
from .params import AbstractMapParams, DynamicsParams, ExplorationParams, ScaleDefaults

FORMAT = "abstract-map/1"


class ModelFileError(ValueError):
    """A saved model that cannot be read."""


def params_to_dict(params: AbstractMapParams) -> dict[str, Any]:
    data = asdict(params)
    data["scales"]["place"] = {f"{a}-{b}": v for (a, b), v in params.scales.place.items()}
    data["scales"]["sign"] = {str(k): v for k, v in params.scales.sign.items()}
    data["scales"]["label"] = {str(k): v for k, v in params.scales.label.items()}
    return data


def params_from_dict(data: dict[str, Any]) -> AbstractMapParams:
    scales = data["scales"]
    return AbstractMapParams(
        scales=ScaleDefaults(
            place={tuple(int(x) for x in k.split("-")): float(v) for k, v in scales["place"].items()},  # type: ignore[misc]
            sign={int(k): float(v) for k, v in scales["sign"].items()},
            label={int(k): float(v) for k, v in scales["label"].items()},
        ),
        dynamics=DynamicsParams(**data["dynamics"]),
        exploration=ExplorationParams(**data["exploration"]),
        start_stiffness=data["start_stiffness"],
        between_angle=data["between_angle"],
    )


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
    }


def from_dict(data: dict[str, Any], *, where: str = "model") -> AbstractMap:
    """Inverse of :func:`to_dict`."""
    if data.get("format") != FORMAT:
        raise ModelFileError(f"{where}: format {data.get('format')!r}, expected {FORMAT!r}")
    try:
        hierarchy = Hierarchy(places=list(data["hierarchy"]["places"]))
        for child, parent in data["hierarchy"]["parent"]:
            hierarchy.add(child, parent, where=where)
        centre = data["explored_centre"]
        return AbstractMap(
            hierarchy=hierarchy,
            start=tuple(data["start"]),  # type: ignore[arg-type]
            params=params_from_dict(data["params"]),
            goal=data["goal"],
            fixed={name: FixedPoint(**f) for name, f in data["fixed"].items()},
            cue_clauses={name: [clause_from_dict(c) for c in cs] for name, cs in data["cue_clauses"].items()},
            loose_clauses=[clause_from_dict(c) for c in data["loose_clauses"]],
            positions={n: np.array(xy, dtype=float) for n, xy in data["positions"].items()},
            velocities={n: np.array(xy, dtype=float) for n, xy in data["velocities"].items()},
            exploration_factor=float(data["exploration_factor"]),
            explored_centre=None if centre is None else np.array(centre, dtype=float),
            start_roots=list(data["start_roots"]),
        )
    except (KeyError, TypeError) as exc:
        raise ModelFileError(f"{where}: missing or malformed field ({exc!r})") from exc


def save(model: AbstractMap, path: str | os.PathLike[str]) -> None:
    """Write the model to a JSON file."""
    Path(path).write_text(json.dumps(to_dict(model), indent=1))


def load(path: str | os.PathLike[str]) -> AbstractMap:
    """Read a model written by :func:`save`."""
    try:
        data = json.loads(Path(path).read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise ModelFileError(f"{path}: cannot read model ({exc})") from exc
    return from_dict(data, where=str(path))
