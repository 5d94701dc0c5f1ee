"""Small builders for core tests."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from abstract_map.hierarchy import Hierarchy
from abstract_map.model import AbstractMap


def make_map(tree: dict | None = None, start=(0.0, -10.0, math.pi / 2), goal: str | None = None) -> AbstractMap:
    tree = tree or {"Campus": {"A": {}, "B": {}, "C": {}, "D": {}}}
    return AbstractMap.from_hierarchy(Hierarchy.from_nested(tree), start, goal=goal)


def angle_at(vertex: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """Angle (deg, in (-180, 180]) at ``vertex`` from ``a`` to ``b``, counter-clockwise."""
    da, db = a - vertex, b - vertex
    return math.degrees(math.remainder(math.atan2(db[1], db[0]) - math.atan2(da[1], da[0]), math.tau))


def settle(model: AbstractMap) -> None:
    report = model.settle()
    assert report.settled, f"did not settle in {report.iterations} steps"


def walked(n_cues: int, places: int = 200, *, settled: bool = True) -> tuple[AbstractMap, object]:
    """A model after the first ``n_cues`` cues of a small generated campus walk (``benchmarks/campus.py``),
    settling after each (and asserting each settled, if ``settled``); and the walk."""
    sys.path.append(str(Path(__file__).resolve().parents[2] / "benchmarks"))
    import campus

    walk = campus.generate(places)
    model = AbstractMap.from_hierarchy(Hierarchy.from_nested(walk.tree), walk.start)
    model.set_explored_centre(np.array(walk.start[:2]))
    model.settle()
    for tag, text, pose in walk.cues[:n_cues]:
        model.observe_tag(tag, text, pose)
        report = model.settle()
        assert report.settled or not settled
    return model, walk
