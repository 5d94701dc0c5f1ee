"""Algorithm 1 on pymunk: integrate the spring-mass system until it settles.

Each settle builds a pymunk space from plain state (positions, velocities,
springs) in a fixed order, so the model's state is data and the same state
always settles the same way. One pymunk body per mass: free masses are dynamic
bodies of the configured mass with infinite moment and a circle of radius
``min_separation / 2`` (colliding masses bounce); observed tags and the start
are static bodies. Distance springs are pymunk ``DampedSpring``s; angle
springs and the expansion force are applied every step from ``forces.py``,
evaluated where pymunk is about to move each body so they stay in step with
the springs.
Viscous friction is pymunk's space damping, exact for linear friction.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pymunk
import pymunk.batch

from .forces import ForceField
from .params import DynamicsParams
from .placement import Resolved

_FREE_CATEGORY = 0b1
_READ = pymunk.batch.BodyFields.POSITION | pymunk.batch.BodyFields.VELOCITY


class _BodyState:
    """Bulk access to every body's position, velocity and force through ``pymunk.batch``."""

    def __init__(self, space: pymunk.Space, n_bodies: int) -> None:
        self.space, self.n = space, n_bodies
        self.buffer = pymunk.batch.Buffer()
        self.forces = np.zeros(n_bodies, dtype=np.complex128)
        self.force_buffer = pymunk.batch.Buffer()
        self.force_buffer.set_float_buf(self.forces)

    def read(self) -> tuple[np.ndarray, np.ndarray]:
        """Positions (m) and velocities (m/s) as complex ``x + iy``, in the order bodies were added."""
        self.buffer.clear()
        pymunk.batch.get_space_bodies(self.space, _READ, self.buffer)
        data = np.frombuffer(self.buffer.float_buf(), dtype=np.complex128).reshape(self.n, 2).copy()
        return data[:, 0], data[:, 1]

    def write_forces(self, forces: np.ndarray) -> None:
        """Set every body's force (N, complex) for the next step."""
        self.forces[:] = forces
        pymunk.batch.set_space_bodies(self.space, pymunk.batch.BodyFields.FORCE, self.force_buffer)


@dataclass(frozen=True)
class SettleResult:
    """The outcome of Algorithm 1."""

    settled: bool
    iterations: int
    positions: dict[str, np.ndarray]  # m, world frame, free masses
    velocities: dict[str, np.ndarray]  # m/s
    stopped_by: str = ""  # why it stopped unsettled: "steps" (the step cap) or "time" (the time cap); "" if settled


_CLOCK_EVERY = 16  # steps between looks at the clock under a time cap (a step is tens of microseconds or more)


def _indices(springs: Sequence[Resolved], kind: str, index: Mapping[str, int], width: int) -> tuple[np.ndarray, ...]:
    chosen = [s for s in springs if s.kind == kind]
    ends = np.array([[index[e] for e in s.ends] for s in chosen], dtype=int).reshape(-1, width)
    return (*ends.T, np.array([s.value for s in chosen]), np.array([s.stiffness for s in chosen]))


def angle_lengths(springs: Sequence[Resolved], kind: str, default: float) -> np.ndarray:
    """Per angle spring of ``kind``, the natural length (m) of the stiffest distance spring between its pivot and
    the place it turns (global: reference and figure; relative: vertex and its second place), or ``default``."""
    natural: dict[frozenset[str], Resolved] = {}
    for s in springs:
        key = frozenset(s.ends)
        if s.kind == "distance" and (key not in natural or s.stiffness > natural[key].stiffness):
            natural[key] = s
    return np.array([natural[key].value if (key := frozenset(s.ends[-2:])) in natural else default
                     for s in springs if s.kind == kind], dtype=float)


def settle(positions: Mapping[str, np.ndarray], velocities: Mapping[str, np.ndarray],
           fixed: Mapping[str, np.ndarray], springs: Sequence[Resolved], *,
           expand: Sequence[str], centre: np.ndarray | None, params: DynamicsParams,
           max_steps: int | None = None, deadline: float | None = None) -> SettleResult:
    """Integrate until every free mass has |a| < L_a and |v| < L_v, or a cap: ``max_steps`` steps (default
    ``params.max_iterations``) or the ``time.perf_counter()`` reading ``deadline`` (default none), whichever
    comes first."""
    step_cap = params.max_iterations if max_steps is None else max_steps
    free = list(positions)
    names = free + list(fixed)
    index = {name: i for i, name in enumerate(names)}
    space = pymunk.Space()
    space.damping = math.exp(-params.friction / params.mass)
    bodies: list[pymunk.Body] = []
    for name in free:
        body = pymunk.Body(params.mass, math.inf)
        body.position = tuple(map(float, positions[name]))
        body.velocity = tuple(map(float, velocities.get(name, (0.0, 0.0))))
        shape = pymunk.Circle(body, params.min_separation / 2.0)
        shape.elasticity = 0.5
        shape.filter = pymunk.ShapeFilter(categories=_FREE_CATEGORY, mask=_FREE_CATEGORY)
        space.add(body, shape)
        bodies.append(body)
    for name in fixed:
        body = pymunk.Body(body_type=pymunk.Body.STATIC)
        body.position = tuple(map(float, fixed[name]))
        space.add(body)
        bodies.append(body)
    for s in springs:
        if s.kind == "distance":
            a, b = bodies[index[s.ends[0]]], bodies[index[s.ends[1]]]
            space.add(pymunk.DampedSpring(a, b, (0, 0), (0, 0), s.value, s.stiffness, 0.0))
    n_free = len(free)
    uses_lengths = params.angle_law != "constant"
    field = ForceField(
        len(bodies),
        *_indices(springs, "global_angle", index, 2),
        *_indices(springs, "relative_angle", index, 3),
        expand=np.array([index[n] for n in expand if n in index and index[n] < n_free], dtype=int),
        centre=None if centre is None else complex(float(centre[0]), float(centre[1])),
        expansion=params.expansion, law=params.expansion_law, core=params.angle_core,
        angle_law=params.angle_law,  # the lengths below only the potential law uses
        g_length=angle_lengths(springs, "global_angle", params.angle_length) if uses_lengths else None,
        r_length=angle_lengths(springs, "relative_angle", params.angle_length) if uses_lengths else None,
    )
    state = _BodyState(space, len(bodies))
    pos, velocity = state.read()
    if not np.allclose(pos, [complex(*b.position) for b in bodies]):
        raise RuntimeError("pymunk returned bodies in an unexpected order")
    dv_limit = params.settle_acceleration * params.dt
    settled, iterations = n_free == 0, 0
    stopped_by = ""
    while not settled:
        if iterations >= step_cap:
            stopped_by = "steps"
            break
        if deadline is not None and iterations % _CLOCK_EVERY == 0 and iterations and time.perf_counter() >= deadline:
            stopped_by = "time"
            break
        # Chipmunk moves bodies (x += v dt) before it applies forces and spring impulses, so
        # forces are taken at those positions; a one-step lag would feed energy into the system.
        ahead = pos + velocity * params.dt
        force = field(ahead)
        state.write_forces(force)
        space.step(params.dt)
        iterations += 1
        pos, new_velocity = state.read()
        dv = new_velocity[:n_free] - velocity[:n_free]
        velocity = new_velocity
        # |v| < L_v and |a| < L_a for every free mass, with a = dv / dt
        settled = bool(np.abs(velocity[:n_free]).max() < params.settle_velocity
                       and np.abs(dv).max() < dv_limit)
    return SettleResult(
        settled=settled,
        iterations=iterations,
        stopped_by=stopped_by,
        positions={n: np.array([pos[i].real, pos[i].imag]) for i, n in enumerate(free)},
        velocities={n: np.array([velocity[i].real, velocity[i].imag]) for i, n in enumerate(free)},
    )
