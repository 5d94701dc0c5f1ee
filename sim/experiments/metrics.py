"""Per-trial scores against the oracle (pure functions; distances in metres).

SPL is Anderson et al. (2018), "On Evaluation of Embodied Navigation Agents":
``success x oracle / max(path, oracle)``, 0 for a failed trial, 1 for a
successful trial that travelled no more than the oracle.
"""

from __future__ import annotations

import math


def spl(success: bool, distance_m: float | None, oracle_m: float | None) -> float | None:
    """Success weighted by path length, in [0, 1]; None when the oracle is unknown."""
    if oracle_m is None or not math.isfinite(oracle_m) or oracle_m <= 0:
        return None
    if not success:
        return 0.0
    if distance_m is None or not math.isfinite(distance_m):
        return None
    return oracle_m / max(distance_m, oracle_m)


def oracle_ratio(success: bool, distance_m: float | None, oracle_m: float | None) -> float | None:
    """Distance over the oracle's length for a successful trial (>= 1 up to the grid); None otherwise."""
    if not success or oracle_m is None or distance_m is None or not (oracle_m > 0 and math.isfinite(distance_m)):
        return None
    return distance_m / oracle_m
