"""Algorithm 1 on pymunk, island by island: integrate what a cue disturbs until every mass has settled.

A settle starts from the masses it is told move (new masses, masses still
moving from a capped settle) and those of the masses it is told to test (the
ends of springs added, removed or changed) that fail the wake test: the net
force on them (``forces.py``) would accelerate them at
``DynamicsParams.wake_acceleration`` or more. Those form an island: a pymunk
space (``island.py``) in which they move and every mass their springs reach
is held still where it is. Every ``_EDGE_EVERY`` steps, and whenever the
island passes Algorithm 1's test (|v| < L_v and |a| < L_a for each of its
masses), the masses held still at its edge take the wake test, and those that
fail join it. When none fails and the island is at rest, the settle ends:
every mass it moved passed Algorithm 1's test, and every mass it left still
has |v| < L_v and an acceleration below the wake threshold (under L_a). So a
cue costs time in proportion to what it moves, and a model of any size that
nothing has disturbed costs nothing.

The same state always settles the same way: islands are built from plain
data (names, springs, positions, velocities) and every walk over the springs
follows the model's list of them.
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Collection, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .forces import NetForce
from .island import Island
from .params import DynamicsParams
from .placement import Resolved
from .values import FIELDS

if TYPE_CHECKING:
    from .resolution import SpringField

_CLOCK_EVERY = 16  # steps between looks at the clock under a time cap (a step is tens of microseconds or more)
_EDGE_EVERY = 32  # steps between tests of the masses held still at the island's edge, besides one at each rest


@dataclass(frozen=True)
class SettleResult:
    """The outcome of Algorithm 1."""

    settled: bool
    iterations: int  # steps integrated, all islands together
    positions: dict[str, np.ndarray]  # m, world frame: the free masses that moved (the final island)
    velocities: dict[str, np.ndarray]  # m/s, likewise
    stopped_by: str = ""  # why it stopped unsettled: "steps" (the step cap) or "time" (the time cap); "" if settled
    islands: int = 0  # times masses joined the moving island: 1 + the times masses held still at its edge joined


class SpringIndex:
    """The springs of a model by the masses they touch, kept up to date cue by cue (:meth:`update`).

    A spring that appears twice counts twice. Every walk over it is in the order of the springs' fields
    (``RememberedHash.fields``), so the same state gives the same islands however it was reached.
    """

    def __init__(self, springs: Sequence[Resolved] = ()) -> None:
        self.count: Counter[Resolved] = Counter()
        self.touching: dict[str, dict[Resolved, None]] = {}
        self._between: dict[tuple[str, str], dict[Resolved, None]] = {}  # sorted ends -> distance springs
        self._lengths: dict[tuple[str, str], float | None] = {}  # sorted ends -> l, or None: no distance spring
        self.changed_pairs: set[tuple[str, str]] = set()  # pairs whose distance springs changed (callers clear it)
        self.update(springs, ())

    def update(self, added: Iterable[Resolved], removed: Iterable[Resolved]) -> None:
        """Add and remove springs (each occurrence once)."""
        count, touching, between, lengths, changed = (self.count, self.touching, self._between, self._lengths,
                                                      self.changed_pairs)
        for s in removed:
            left = count[s] - 1
            if left > 0:
                count[s] = left
                continue
            dict.__delitem__(count, s)  # Counter's own __delitem__ is Python, and the key is known to be there
            for end in s.ends:
                touching[end].pop(s, None)
            if s.kind == "distance":
                ends = pair(*s.ends)
                between[ends].pop(s, None)
                lengths.pop(ends, None)
                changed.add(ends)
        for s in added:
            count[s] += 1
            for end in s.ends:
                touching.setdefault(end, {})[s] = None
            if s.kind == "distance":
                ends = pair(*s.ends)
                between.setdefault(ends, {})[s] = None
                lengths.pop(ends, None)
                changed.add(ends)

    def around(self, names: Iterable[str]) -> list[Resolved]:
        """Every spring touching one of ``names``, once each."""
        chosen: dict[Resolved, None] = {}
        for name in names:
            chosen.update(self.touching.get(name, {}))
        return sorted(chosen, key=FIELDS)

    def length(self, spring: Resolved, default: float) -> float:
        """``l`` (m) of an angle spring: the natural length of the stiffest distance spring between its pivot
        and the place it turns (global: reference and figure; relative: vertex and its second place)."""
        ends = pair(*spring.ends[-2:])  # pivot and turned place
        if ends not in self._lengths:
            # the stiffest; of equals, the first in field order (not the order the index met them in)
            best = min(self._between.get(ends, {}), key=lambda s: (-s.stiffness, s.fields), default=None)
            self._lengths[ends] = None if best is None else best.value
        length = self._lengths[ends]
        return default if length is None else length


def pair(a: str, b: str) -> tuple[str, str]:
    """Two names in a fixed order: the key of the springs between them."""
    return (a, b) if a <= b else (b, a)


class ComplexPositions(dict):  # type: ignore[type-arg]
    """Complex positions (m) by name, filled from plain ``(x, y)`` mappings when first asked for."""

    def __init__(self, *sources: Mapping[str, Any]) -> None:
        super().__init__()
        self.sources = sources

    def __missing__(self, name: str) -> complex:
        for source in self.sources:
            if name in source:
                x, y = source[name]
                value = self[name] = complex(float(x), float(y))
                return value
        raise KeyError(name)


def settle(positions: Mapping[str, np.ndarray], velocities: Mapping[str, np.ndarray],
           fixed: Mapping[str, np.ndarray], springs: Sequence[Resolved] | SpringIndex, *,
           active: Iterable[str], expand: Iterable[str], centre: np.ndarray | None, params: DynamicsParams,
           tested: Iterable[str] = (), field: SpringField | None = None, max_steps: int | None = None,
           deadline: float | None = None) -> SettleResult:
    """Settle the masses ``active``, those of ``tested`` that fail the acceleration test, and whatever they
    disturb; every other free mass of ``positions`` is held still until the net force on it would accelerate
    it at ``params.wake_acceleration`` or more.

    ``field``, if given, is the same springs as arrays (a prepared ``resolution.SpringField``), from which
    the forces on masses held still are gathered instead of built spring by spring.

    Stops settled, or at a cap: ``max_steps`` steps in all (default ``params.max_iterations``) or the
    ``time.perf_counter()`` reading ``deadline`` (default none), whichever comes first."""
    step_cap = params.max_iterations if max_steps is None else max_steps
    index = springs if isinstance(springs, SpringIndex) else SpringIndex(springs)
    where = ComplexPositions(positions, fixed)
    speed = ComplexPositions(velocities, _Zero())
    expand = expand if isinstance(expand, (set, frozenset, dict)) else set(expand)
    names = list(dict.fromkeys(n for n in active if n in positions))
    inside = set(names)
    names += _failing([n for n in dict.fromkeys(tested) if n in positions and n not in inside], index, where,
                      expand, centre, params, field)
    island = Island(index, fixed, expand=expand, centre=centre, params=params)
    steps, joins, stopped_by = 0, 0, ""
    dv_limit = params.settle_acceleration * params.dt
    joining = names
    while joining:
        island.join(joining, where, speed, index.around(joining))
        joins += 1
        joining = []
        z, velocity = island.read()
        if not np.allclose(z, [where[n] for n in island.names]):
            raise RuntimeError("pymunk returned bodies in an unexpected order")
        woken = _EdgeTest(island, index, where, params, field)
        while True:
            if steps >= step_cap:
                stopped_by = "steps"
                break
            if deadline is not None and steps % _CLOCK_EVERY == 0 and steps and time.perf_counter() >= deadline:
                stopped_by = "time"
                break
            island.step(z, velocity)
            steps += 1
            z, after = island.read()
            # |v| < L_v and |a| < L_a for every island mass, with a = dv / dt
            at_rest = bool(np.abs(after).max() < params.settle_velocity
                           and np.abs(after - velocity).max() < dv_limit)
            velocity = after
            if at_rest or steps % _EDGE_EVERY == 0:
                joining = woken(z)
                if joining or at_rest:
                    where.update(zip(island.names, z))
                    speed.update(zip(island.names, velocity))
                    break
        if stopped_by:
            break
    z, v = island.read()
    where.update(zip(island.names, z))
    speed.update(zip(island.names, v))
    return SettleResult(
        settled=not stopped_by, iterations=steps, stopped_by=stopped_by, islands=joins,
        positions={n: np.array([where[n].real, where[n].imag]) for n in island.names},
        velocities={n: np.array([speed[n].real, speed[n].imag]) for n in island.names},
    )


class _Zero:
    """Every name's velocity (m/s) when none is given: at rest."""

    def __contains__(self, name: object) -> bool:
        return True

    def __getitem__(self, name: str) -> tuple[float, float]:
        return 0.0, 0.0


class _EdgeTest:
    """The wake test of the masses an island holds still at its edge, made once for each shape of the island
    (:meth:`Island.join` changes it): called with the island's positions, it returns those that fail."""

    def __init__(self, island: Island, index: SpringIndex, where: Mapping[str, complex], params: DynamicsParams,
                 field: SpringField | None = None) -> None:
        self.edge = list(island.edge)
        self.net = _net_force(self.edge, index, island.expand, island.centre, params, field)
        inside = {name: i for i, name in enumerate(island.names)}
        mine = [(k, inside[n]) for k, n in enumerate(self.net.slots) if n in inside]
        self.slot, self.of_island = (np.array(x, dtype=int) for x in zip(*mine)) if mine else \
            (np.zeros(0, dtype=int), np.zeros(0, dtype=int))
        self.z = np.array([where[n] for n in self.net.slots], dtype=complex)  # the rest hold still
        self.limit = params.wake_acceleration * params.mass

    def __call__(self, z: np.ndarray) -> list[str]:
        if not self.edge:
            return []
        self.z[self.slot] = z[self.of_island]
        force = np.abs(self.net(self.z))
        return [self.edge[i] for i in np.flatnonzero(force >= self.limit)]


def _net_force(names: Sequence[str], index: SpringIndex, expanding: Collection[str], centre: np.ndarray | None,
               params: DynamicsParams, field: SpringField | None = None) -> NetForce:
    """The net force on ``names`` from every spring touching them (each as often as it occurs) and expansion;
    gathered from ``field`` (a prepared ``resolution.SpringField``) if given."""
    laws = {"expand": [e in expanding for e in names],
            "centre": None if centre is None else complex(float(centre[0]), float(centre[1])),
            "expansion": params.expansion, "law": params.expansion_law, "core": params.core}
    if field is not None:
        return field.around(names, **laws)
    around = [s for s in index.around(names) for _ in range(index.count[s])]
    return NetForce(names, around, [index.length(s, params.angle_length) if s.kind != "distance" else 0.0
                                    for s in around], **laws)


def _failing(names: Sequence[str], index: SpringIndex, where: Mapping[str, complex], expanding: Collection[str],
             centre: np.ndarray | None, params: DynamicsParams, field: SpringField | None = None) -> list[str]:
    """Those of ``names`` (masses held still) on which the net force would accelerate them at
    ``params.wake_acceleration`` or more, in ``names`` order."""
    if not names:
        return []
    net = _net_force(names, index, expanding, centre, params, field)
    force = net(np.array(list(map(where.__getitem__, net.slots)), dtype=complex))
    limit = params.wake_acceleration * params.mass
    return [e for e, f in zip(names, force) if abs(f) >= limit]
