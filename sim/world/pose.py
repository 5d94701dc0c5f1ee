"""Checking a robot pose given by a caller: (x m, y m, theta rad) in the world frame."""

from __future__ import annotations

import numpy as np


def check_pose(pose: tuple[float, float, float] | np.ndarray, name: str = "pose") -> tuple[float, float, float]:
    """``pose`` as three finite floats (x m, y m, theta rad); ValueError naming it otherwise."""
    values = np.asarray(pose, dtype=float).ravel()
    if values.shape != (3,) or not np.all(np.isfinite(values)):
        raise ValueError(f"{name} must be three finite numbers (x m, y m, theta rad), got {pose!r}")
    return float(values[0]), float(values[1]), float(values[2])
