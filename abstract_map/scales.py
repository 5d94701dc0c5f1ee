"""Scale factors: metres per unit natural length, by pair of hierarchy levels.

Defaults come from :class:`~abstract_map.params.ScaleDefaults`. Once both ends
of a distance spring have been observed, its observed length ``r_o`` gives the
ratio ``r_o / r_n``; the factor for that pair of levels becomes the
stiffness-weighted mean of those ratios (equation 7 of the paper). Label and
start springs are assumptions about reading distance and are never learned.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from .clauses import is_anchor
from .params import ScaleDefaults
from .springs import Spring

ScaleKey = tuple  # ("place", a, b) with a <= b, or ("sign" | "label" | "start", level)
LEARNABLE = ("place", "sign")


def _clamp(level: int, table: Mapping) -> int:
    top = max(k if isinstance(k, int) else max(k) for k in table)
    return min(level, top)


def scale_key(spring: Spring, levels: Mapping[str, int]) -> ScaleKey:
    """Which scale factor a distance spring uses."""
    a, b = spring.ends[0], spring.ends[1]
    if spring.scale == "place":
        la, lb = sorted((levels.get(a, 1), levels.get(b, 1)))
        return ("place", la, lb)
    place = b if is_anchor(a) else a
    return (spring.scale, levels.get(place, 1))


def default_scale(key: ScaleKey, defaults: ScaleDefaults) -> float:
    """The default metres per unit for a key; levels past a table's top use its top."""
    if key[0] == "place":
        la, lb = _clamp(key[1], defaults.place), _clamp(key[2], defaults.place)
        return defaults.place[(la, lb)]
    table = {"sign": defaults.sign, "label": defaults.label, "start": defaults.label}[key[0]]
    return table[_clamp(key[1], table)]


def learn_scales(springs: Sequence[Spring], levels: Mapping[str, int],
                 observed: Callable[[str], np.ndarray | None]) -> dict[ScaleKey, float]:
    """Equation 7: per key, the stiffness-weighted mean of observed / natural length ratios.

    ``observed(name)`` gives the observed world position of a place or anchor, or None.
    """
    sums: dict[ScaleKey, list[float]] = {}
    for spring in springs:
        if spring.kind != "distance" or spring.scale not in LEARNABLE:
            continue
        ends = [observed(e) for e in spring.ends[:2]]
        if ends[0] is None or ends[1] is None:
            continue
        r_o = float(math.hypot(*(ends[0] - ends[1])))
        key = scale_key(spring, levels)
        acc = sums.setdefault(key, [0.0, 0.0])
        acc[0] += spring.stiffness * r_o / spring.value
        acc[1] += spring.stiffness
    return {key: total / weight for key, (total, weight) in sums.items() if weight > 0 and total > 0}


def natural_lengths(springs: Sequence[Spring], levels: Mapping[str, int], learned: Mapping[ScaleKey, float],
                    defaults: ScaleDefaults, exploration: float) -> list[float]:
    """Natural length (m) of every distance spring, units x scale x exploration (labels are not explored);
    0 for angle springs. Each scale factor is looked up once."""
    alpha: dict[ScaleKey, float] = {}
    out = []
    for spring in springs:
        if spring.kind != "distance":
            out.append(0.0)
            continue
        key = scale_key(spring, levels)
        if key not in alpha:
            alpha[key] = learned.get(key, default_scale(key, defaults))
        out.append(spring.value * alpha[key] * (1.0 if spring.scale == "label" else exploration))
    return out
