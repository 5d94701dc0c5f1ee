"""A pymunk space for one island of the spring system, which grows as held-still masses join it.

An island is the set of free masses a settle moves. Its masses are dynamic
bodies of the configured mass, with infinite moment and a collision circle of
radius ``min_separation / 2`` (colliding masses bounce); every other mass one
of its springs reaches (a free mass held still, or a fixed point) is a static
body where it is. Inside Chipmunk's solver:

- each distance spring is a ``DampedSpring`` (no damping: friction is the
  space's, exact for linear friction);
- the expansion force is a ``DampedSpring`` from the explored centre to each
  expanding mass: rest length ``_FAR`` and stiffness ``c / _FAR`` push with
  ``c (1 - r / _FAR)``, a constant ``c`` to 0.2 % within the coordinate
  range (constant law); rest length 0 and stiffness ``-c`` push with ``c r``
  (proportional law).

The angle springs act from numpy (``forces.AngleSprings``), written into
Chipmunk as each step's body forces. Frames: world, metres, radians.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Iterable, Mapping
from typing import Any

import numpy as np
import pymunk
import pymunk.batch

from .forces import AngleSprings
from .params import DynamicsParams
from .placement import Resolved

_FREE_CATEGORY = 0b1
_READ = pymunk.batch.BodyFields.POSITION | pymunk.batch.BodyFields.VELOCITY
_FAR = 1.0e9  # m, rest length of a constant-law expansion spring: 1,000 times the coordinate range
EXPANSION_SPRINGS = {  # law -> (rest length m, stiffness N/m) for a push of c (N or N/m)
    "constant": lambda c: (_FAR, c / _FAR),
    "proportional": lambda c: (0.0, -c),
}


class Island:
    """A pymunk space holding an island; masses held still at its edge :meth:`join` it as they are woken.

    ``names`` are the island's masses in the order they joined, which is also pymunk's order of its
    dynamic bodies. ``index`` (a ``dynamics.SpringIndex``) gives each spring's multiplicity and each angle
    spring's ``l``.
    """

    def __init__(self, index: Any, fixed: Mapping[str, np.ndarray], *, expand: Collection[str],
                 centre: np.ndarray | None, params: DynamicsParams) -> None:
        self.index, self.fixed, self.params = index, fixed, params
        self.space = pymunk.Space()
        self.space.damping = math.exp(-params.friction / params.mass)
        self.space.iterations = params.solver_iterations
        self.names: list[str] = []
        self.moving: set[str] = set()  # the names, as a set
        self.bodies: dict[str, pymunk.Body] = {}  # every mass in the space, moving or held still
        self.added: dict[Resolved, None] = {}  # the springs in the island, in the order they joined
        self.edge: dict[str, None] = {}  # the free masses its springs reach that it holds still, in order met
        self.expand, self.centre = expand, centre
        self.hub: pymunk.Body | None = None
        if centre is not None and params.expansion != 0.0:
            self.hub = pymunk.Body(body_type=pymunk.Body.STATIC)
            self.hub.position = _xy(centre)
            self.space.add(self.hub)
        self._buffer = pymunk.batch.Buffer()
        self._forces = np.zeros(0, dtype=complex)
        self._force_buffer = pymunk.batch.Buffer()
        self._angles = AngleSprings(0, [], [], [], core=params.core)
        self._still = np.zeros(0, dtype=complex)  # positions (m) of the masses the angle springs hold still

    @property
    def n(self) -> int:
        return len(self.names)

    def join(self, names: Iterable[str], positions: Mapping[str, complex], velocities: Mapping[str, complex],
             springs: Iterable[Resolved]) -> None:
        """Set ``names`` moving (from complex ``positions`` m, ``velocities`` m/s) and add the ``springs`` not yet
        in the island; every other end of theirs is held still where ``positions`` puts it."""
        params = self.params
        for name in names:
            body = self.bodies.get(name)
            if body is None:
                body = self.bodies[name] = pymunk.Body(params.mass, math.inf)
                body.position = _xy(positions[name])
                self.space.add(body)
            else:  # held still until now: Chipmunk moves it to the end of its dynamic bodies
                body.body_type = pymunk.Body.DYNAMIC
                body.mass, body.moment = params.mass, math.inf
            _add_circle(self.space, body, params)
            body.velocity = _xy(velocities[name])
            self.names.append(name)
            self.moving.add(name)
            self.edge.pop(name, None)
            if self.hub is not None and name in self.expand:
                rest, stiffness = EXPANSION_SPRINGS[params.expansion_law](params.expansion)
                self.space.add(pymunk.DampedSpring(self.hub, body, (0, 0), (0, 0), rest, stiffness, 0.0))
        for s in springs:
            if s in self.added:
                continue
            self.added[s] = None
            for end in s.ends:
                if end not in self.fixed and end not in self.moving:
                    self.edge[end] = None
            if s.kind == "distance":
                a, b = self._body(s.ends[0], positions), self._body(s.ends[1], positions)
                for _ in range(self.index.count[s]):
                    self.space.add(pymunk.DampedSpring(a, b, (0, 0), (0, 0), s.value, s.stiffness, 0.0))
            else:
                for end in s.ends:
                    self._body(end, positions)
        self._index_angles()

    def read(self) -> tuple[np.ndarray, np.ndarray]:
        """Positions (m) and velocities (m/s) of the island's masses, complex ``x + iy``, in ``names`` order."""
        self._buffer.clear()
        pymunk.batch.get_space_bodies(self.space, _READ, self._buffer)
        data = np.frombuffer(self._buffer.float_buf(), dtype=np.complex128).reshape(-1, 2)[:self.n]
        return data[:, 0].copy(), data[:, 1].copy()

    def step(self, z: np.ndarray, v: np.ndarray) -> None:
        """One step of ``params.dt``, from positions ``z`` and velocities ``v`` (as :meth:`read` gives them)."""
        if len(self._angles):
            # Chipmunk moves bodies (x += v dt) before it applies forces and spring impulses, so the angle
            # springs are taken at those positions; a one-step lag would feed energy into the system.
            self._forces[:self.n] = self._angles(np.concatenate([z + v * self.params.dt, self._still]))[:self.n]
            pymunk.batch.set_space_bodies(self.space, pymunk.batch.BodyFields.FORCE, self._force_buffer)
        self.space.step(self.params.dt)

    def _body(self, name: str, positions: Mapping[str, complex]) -> pymunk.Body:
        body = self.bodies.get(name)
        if body is None:  # held still: a static body where it is
            body = self.bodies[name] = pymunk.Body(body_type=pymunk.Body.STATIC)
            body.position = _xy(positions[name])
            self.space.add(body)
        return body

    def _index_angles(self) -> None:
        """The island's angle springs over its masses (slots 0..n-1) and those they hold still (after)."""
        chosen = [s for s in self.added if s.kind != "distance" for _ in range(self.index.count[s])]
        slot = {name: i for i, name in enumerate(self.names)}
        for s in chosen:
            for end in s.ends:
                slot.setdefault(end, len(slot))
        still = list(slot)[self.n:]
        self._still = np.array([complex(*self.bodies[name].position) for name in still], dtype=complex)
        lengths = [self.index.length(s, self.params.angle_length) for s in chosen]
        self._angles = AngleSprings(len(slot), chosen, [[slot[e] for e in s.ends] for s in chosen], lengths,
                                    core=self.params.core)
        self._forces = np.zeros(len(self.space.bodies), dtype=complex)  # pymunk's order: the island's first
        self._force_buffer = pymunk.batch.Buffer()
        self._force_buffer.set_float_buf(self._forces)


def _xy(value: complex | Iterable[float]) -> tuple[float, float]:
    if isinstance(value, complex):
        return value.real, value.imag
    x, y = value
    return float(x), float(y)


def _add_circle(space: pymunk.Space, body: pymunk.Body, params: DynamicsParams) -> None:
    """A moving mass's collision circle (radius ``min_separation / 2``; colliding masses bounce)."""
    if params.min_separation > 0:
        shape = pymunk.Circle(body, params.min_separation / 2.0)
        shape.elasticity = 0.5
        shape.filter = pymunk.ShapeFilter(categories=_FREE_CATEGORY, mask=_FREE_CATEGORY)
        space.add(shape)
