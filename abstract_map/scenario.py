"""Scenario replay: feed a sequence of cues to an abstract map and record every settle.

A scenario is JSON::

    {"hierarchy": "zoo_hierarchy.xml" | {"Campus": {"A Block": {"Room 1": {}}}},
     "start": [x_m, y_m, heading_deg],
     "goal": "Lion",                                   (optional)
     "steps": [{"text": "...", "tag": 3, "pose": [x_m, y_m, theta_deg]},
               {"text": "The Lion is past the Giraffe"}, ...]}

A hierarchy path is relative to the scenario file. ``tag`` and ``pose`` go
together; a step without them is a cue with no place in the world. Optional
step keys: ``kind`` ("label" or "sign", else inferred from the text) and
``explored_centre`` ([x_m, y_m]); without the latter the centre of explored
space is the mean of the start and every cue pose so far.
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

from . import errors
from .clauses import tag_anchor
from .errors import ScenarioError
from .grammar import Anchor, parse_cue
from .hierarchy import Hierarchy
from .model import AbstractMap, SettleReport, imagined_positions
from .params import AbstractMapParams

_SCENARIO_KEYS = {"hierarchy", "start", "goal", "steps"}
_STEP_KEYS = {"text", "tag", "pose", "kind", "explored_centre"}



@dataclass(frozen=True)
class Step:
    """One cue of a scenario."""

    text: str
    tag: int | None = None
    pose: tuple[float, float, float] | None = None  # x m, y m, theta rad
    kind: str | None = None
    explored_centre: tuple[float, float] | None = None

    def anchor(self) -> Anchor | None:
        """The tag this cue was read on, as a fixed point, or None for a cue with no place."""
        if self.pose is None or self.tag is None:
            return None
        return Anchor(tag_anchor(self.tag), *self.pose)


@dataclass
class Scenario:
    hierarchy: Hierarchy
    start: tuple[float, float, float]  # x m, y m, heading rad
    steps: list[Step] = field(default_factory=list)
    goal: str | None = None


def _keys(where: str, data: Any, allowed: set[str], required: set[str]) -> None:
    if not isinstance(data, dict):
        raise ScenarioError(f"{where}: expected a JSON object, got {type(data).__name__}")
    for key in data:
        if key not in allowed:
            hint = difflib.get_close_matches(key, sorted(allowed), n=1)
            raise ScenarioError(f"{where}: unknown key {key!r}" + (f" (did you mean {hint[0]!r}?)" if hint else "")
                                + f"; expected {sorted(allowed)}")
    missing = required - set(data)
    if missing:
        raise ScenarioError(f"{where}: missing key(s) {sorted(missing)}")


def _numbers(where: str, value: Any, n: int) -> list[float]:
    """[x m, y m] or [x m, y m, angle deg]: finite, coordinates and angle within the ranges of :mod:`errors`."""
    if not isinstance(value, list) or len(value) != n:
        raise ScenarioError(f"{where}: expected a list of {n} numbers, got {errors.show(value)}")
    names = ("x", "y", "angle")
    return [errors.coordinate(f"{where} {names[i]}", v, ScenarioError) if i < 2
            else errors.angle(f"{where} {names[i]}", v, ScenarioError) for i, v in enumerate(value)]


def _step(where: str, data: Any) -> Step:
    _keys(where, data, _STEP_KEYS, {"text"})
    if not isinstance(data["text"], str) or not data["text"].strip():
        raise ScenarioError(f"{where}: 'text' must be non-empty text")
    if ("tag" in data) != ("pose" in data):
        raise ScenarioError(f"{where}: 'tag' and 'pose' go together")
    if data.get("kind") not in (None, "label", "sign"):
        raise ScenarioError(f"{where}: 'kind' must be 'label' or 'sign', got {errors.show(data['kind'])}")
    pose = None
    if "pose" in data:
        x, y, theta = _numbers(f"{where} pose", data["pose"], 3)
        pose = (x, y, math.radians(theta))
        errors.tag_id(f"{where} tag", data["tag"], ScenarioError)
    centre = data.get("explored_centre")
    return Step(data["text"], data.get("tag"), pose, data.get("kind"),
                None if centre is None else tuple(_numbers(f"{where} explored_centre", centre, 2)))  # type: ignore[arg-type]


def load_scenario(path: str | os.PathLike[str]) -> Scenario:
    """Read and check a scenario file."""
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ScenarioError(f"{path}: cannot read scenario ({exc.strerror or exc})") from exc
    except (ValueError, RecursionError) as exc:  # JSONDecodeError and UnicodeDecodeError are ValueErrors
        raise ScenarioError(f"{path}: not valid JSON ({errors.one_line(str(exc), 120)})") from None
    where = str(path)
    _keys(where, data, _SCENARIO_KEYS, {"hierarchy", "start", "steps"})
    spec = data["hierarchy"]
    if isinstance(spec, str):
        hierarchy = Hierarchy.from_xml(path.parent / spec)
    elif isinstance(spec, dict):
        hierarchy = Hierarchy.from_nested(spec, where=f"{where} hierarchy")
    else:
        raise ScenarioError(f"{where}: 'hierarchy' must be a path to XML or a nested object, got {spec!r}")
    x, y, heading = _numbers(f"{where} start", data["start"], 3)
    if not isinstance(data["steps"], list):
        raise ScenarioError(f"{where}: 'steps' must be a list")
    if data.get("goal") is not None:
        errors.place_name(f"{where} goal", data["goal"], error=ScenarioError)
    steps = [_step(f"{where} step {i}", s) for i, s in enumerate(data["steps"])]
    scenario = Scenario(hierarchy, (x, y, math.radians(heading)), steps, data.get("goal"))
    _check_goal(scenario, where)
    return scenario


def _check_goal(scenario: Scenario, where: str) -> None:
    """A goal must be named by the hierarchy or by some step's cue."""
    if scenario.goal is None:
        return
    names = {p.casefold() for p in scenario.hierarchy.places}
    for step in scenario.steps:
        for clause in parse_cue(step.text, step.anchor(), kind=step.kind):
            names.update(n.casefold() for n in vars(clause).values() if isinstance(n, str))
            names.update(r.casefold() for r in getattr(clause, "referents", ()))
    if scenario.goal.casefold() not in names:
        raise ScenarioError(f"{where}: goal {scenario.goal!r} is not mentioned by the hierarchy or any step")


def _record(model: AbstractMap, report: SettleReport, label: str) -> dict[str, Any]:
    goal = None
    if model.goal is not None:
        goal = [float(v) for v in model.goal_estimate()]
    return {"cue": label, "settled": report.settled, "stopped_by": report.stopped_by, "iterations": report.iterations,
            "wall_s": round(report.wall_s, 6), "exploration_factor": model.exploration_factor,
            "positions": {n: [round(x, 6), round(y, 6)] for n, (x, y) in imagined_positions(model).items()},
            "goal": goal}


Progress = Callable[[int, int, dict[str, Any]], None]
"""Called after each settle with (step, steps, record)."""


def replay(scenario: Scenario, *, params: AbstractMapParams | None = None,
           progress: Progress | None = None, max_steps: int | None = None,
           max_s: float | None = None) -> tuple[AbstractMap, list[dict[str, Any]]]:
    """Settle after the hierarchy and after every step; one record per settle. ``max_steps`` and ``max_s``
    cap each settle (:meth:`AbstractMap.settle`)."""
    model = AbstractMap.from_hierarchy(scenario.hierarchy, scenario.start, goal=scenario.goal, params=params)
    visited = [np.array(scenario.start[:2])]
    model.set_explored_centre(visited[0])
    records = [_record(model, model.settle(max_steps=max_steps, max_s=max_s), "hierarchy")]
    if progress:
        progress(0, len(scenario.steps), records[-1])
    for i, step in enumerate(scenario.steps, start=1):
        if step.pose is not None and step.tag is not None:
            model.observe_tag(step.tag, step.text, step.pose, kind=step.kind)
            visited.append(np.array(step.pose[:2]))
            label = f"tag {step.tag}"
        else:
            model.add_clauses(parse_cue(step.text, kind=step.kind))
            label = "untagged cue"
        model.set_explored_centre(step.explored_centre if step.explored_centre is not None
                                  else np.mean(visited, axis=0))
        records.append(_record(model, model.settle(max_steps=max_steps, max_s=max_s), label))
        if progress:
            progress(i, len(scenario.steps), records[-1])
    return model, records
