"""Algorithm 2: give new point masses a starting position.

New masses are placed one at a time, the most constrained first (descending
total stiffness of attached springs), each where its springs to masses already
placed are best satisfied, with zero velocity. A mass held only by distance
springs to a single placed neighbour is fanned out ahead of that neighbour
(away from the start), so that siblings do not start on top of each other.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from .values import RememberedHash

GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


@dataclass(frozen=True)
class Resolved(RememberedHash):
    """A spring with its natural value in SI units: metres (distance) or radians (angles)."""

    kind: str
    ends: tuple[str, ...]
    value: float
    stiffness: float

    __hash__ = RememberedHash.__hash__  # in the class body, or the dataclass would write its own


def _fan_angle(k: int) -> float:
    """The k-th fan offset (rad) in [-pi/2, pi/2), starting straight ahead."""
    return math.pi * (((k * GOLDEN) + 0.5) % 1.0 - 0.5)


def _unit(angle: float) -> np.ndarray:
    return np.array([math.cos(angle), math.sin(angle)])


def _fit_distances(x0: np.ndarray, points: np.ndarray, lengths: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Least-squares point at the given distances from ``points`` (gradient descent from ``x0``)."""
    x = x0.astype(float).copy()
    step = 0.5 / max(float(weights.sum()), 1e-9)
    for _ in range(200):
        d = x - points
        r = np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-9)
        grad = ((weights * (r - lengths) / r)[:, None] * d).sum(axis=0)
        x -= step * grad
        if float(np.hypot(*grad)) < 1e-6:
            break
    return x


def place_new_masses(new: Sequence[str], known: Mapping[str, np.ndarray], springs: Sequence[Resolved], *,
                     origin: np.ndarray, heading: float, min_separation: float) -> dict[str, np.ndarray]:
    """Starting positions (m, world) for the masses ``new`` given the ``known`` ones."""
    placed = {name: np.asarray(p, dtype=float) for name, p in known.items()}
    touching: dict[str, list[Resolved]] = {}
    for spring in springs:
        for end in set(spring.ends):
            touching.setdefault(end, []).append(spring)
    total = {name: sum(s.stiffness for s in touching.get(name, [])) for name in new}
    order = sorted(new, key=lambda n: -total[n])  # stable: ties keep first-seen order
    rank = {name: i for i, name in enumerate(order)}
    ready: list[int] = []  # ranks of unplaced masses with a spring whose other ends are all placed

    def offer(name: str) -> None:
        for spring in touching.get(name, []):
            if all(e in placed for e in spring.ends if e != name):
                heapq.heappush(ready, rank[name])
                return

    for name in order:
        offer(name)
    fan_count: dict[str, int] = {}
    crowded: dict[tuple[int, int], int] = {}  # spiral turns used around each crowded spot
    result: dict[str, np.ndarray] = {}
    points = np.zeros((len(placed) + len(order), 2))  # every placed position, for the separation check
    points[:len(placed)] = list(placed.values()) if placed else np.zeros((0, 2))
    count = len(placed)
    waiting = list(reversed(order))  # for masses with no placed neighbour: the first in order
    while len(result) < len(order):
        name = None
        while ready and name is None:
            candidate = order[heapq.heappop(ready)]
            name = None if candidate in result else candidate
        while name is None:
            candidate = waiting.pop()
            name = None if candidate in result else candidate
        mine = touching.get(name, [])
        position = _best_position(name, mine, placed, fan_count, origin=origin, heading=heading)
        position = _separate(position, points[:count], min_separation, crowded)
        placed[name] = result[name] = position
        points[count] = position
        count += 1
        for spring in mine:
            for other in spring.ends:
                if other in rank and other not in result:
                    offer(other)
    return result


def _length_between(name: str, other: str, springs: Sequence[Resolved], fallback: float) -> float:
    lengths = [s.value for s in springs if s.kind == "distance" and set(s.ends) == {name, other}]
    return lengths[0] if lengths else fallback


def _best_position(name: str, springs: Sequence[Resolved], placed: Mapping[str, np.ndarray],
                   fan_count: dict[str, int], *, origin: np.ndarray, heading: float) -> np.ndarray:
    """Where ``name`` best satisfies ``springs`` (those touching it) to the placed masses."""
    distance = [s for s in springs if s.kind == "distance" and name in s.ends
                and all(e in placed for e in s.ends if e != name)]
    typical = float(np.mean([s.value for s in distance])) if distance else 1.0
    candidates: list[tuple[np.ndarray, float]] = []
    for s in springs:
        if name not in s.ends or not all(e in placed for e in s.ends if e != name):
            continue
        if s.kind == "global_angle" and s.ends[1] == name:
            ref = placed[s.ends[0]]
            candidates.append((ref + _length_between(name, s.ends[0], springs, typical) * _unit(s.value),
                               s.stiffness))
        elif s.kind == "relative_angle" and s.ends[2] == name:
            a, vertex = placed[s.ends[0]], placed[s.ends[1]]
            base = math.atan2(*(a - vertex)[::-1])
            length = _length_between(name, s.ends[1], springs, typical)
            candidates.append((vertex + length * _unit(base + s.value), s.stiffness))
        elif s.kind == "relative_angle" and s.ends[1] == name and abs(abs(s.value) - math.pi) < 1e-9:
            a, b = placed[s.ends[0]], placed[s.ends[2]]
            ab = a - b
            norm = float(np.hypot(*ab))
            if norm > 1e-9:
                length = min(_length_between(name, s.ends[2], springs, typical), norm)
                candidates.append((b + length * ab / norm, s.stiffness))
    if candidates:
        weights = np.array([w for _, w in candidates])
        return (np.array([c for c, _ in candidates]) * weights[:, None]).sum(axis=0) / weights.sum()
    if not distance:
        k = fan_count.get("", 0)
        fan_count[""] = k + 1
        return origin + (1.0 + k) * _unit(heading + _fan_angle(k))
    others = [s.ends[0] if s.ends[1] == name else s.ends[1] for s in distance]
    points = np.array([placed[o] for o in others])
    lengths = np.array([s.value for s in distance])
    weights = np.array([s.stiffness for s in distance])
    if len(set(others)) == 1:
        anchor = others[0]
        away = points[0] - origin
        outward = math.atan2(away[1], away[0]) if float(np.hypot(*away)) > 1e-6 else heading
        k = fan_count.get(anchor, 0)
        fan_count[anchor] = k + 1
        return points[0] + float(lengths.mean()) * _unit(outward + _fan_angle(k))
    centroid = (points * weights[:, None]).sum(axis=0) / weights.sum()
    k = fan_count.get("*", 0)
    fan_count["*"] = k + 1
    start = centroid + float(lengths.mean()) * 0.5 * _unit(heading + _fan_angle(k))
    return _fit_distances(start, points, lengths, weights)


def _separate(position: np.ndarray, points: np.ndarray, min_separation: float,
              crowded: dict[tuple[int, int], int] | None = None) -> np.ndarray:
    """Nudge a position so that it keeps ``min_separation`` (m) from every point of ``points`` (M, 2).

    Sixteen nudges around the spot first; if all are taken (many masses sharing one spot, e.g. a
    sign with hundreds of arrows one way), the first free point of a golden-angle spiral about the
    spot, continuing where the last mass placed there left off, so n masses at one spot cost O(n)
    tries and none overlaps (overlapping masses make pymunk's collision work quadratic).
    """
    original = position
    position = position.copy()
    for k in range(16):
        if _free(position, points, min_separation):
            return position
        position = position + min_separation * _unit(_fan_angle(k + 1) * 2.0)
    if min_separation <= 0 or crowded is None:
        return position
    key = (int(round(original[0] / min_separation)), int(round(original[1] / min_separation)))
    k = crowded.get(key, 0)
    while True:
        k += 1
        candidate = original + min_separation * math.sqrt(k) * _unit(k * math.tau * GOLDEN)
        if _free(candidate, points, min_separation):
            crowded[key] = k
            return candidate


def _free(position: np.ndarray, points: np.ndarray, min_separation: float) -> bool:
    return len(points) == 0 or float(np.hypot(*(points - position).T).min()) >= min_separation
