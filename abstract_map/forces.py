"""The forces that act outside pymunk's solver, in numpy: angle springs, and every force on masses held still.

Positions are complex numbers ``x + iy`` in metres (world frame); forces are
newtons, complex likewise.

- angle spring (the potential law): the force of the energy
  ``K l error^2 / 2``, pushing each place it turns tangentially with
  ``K l error / r`` at distance ``r`` from its pivot, the pivot taking the
  reaction; ``l`` is the natural length of the stiffest distance spring
  between the pivot and the place it turns (so at ``r = l`` the force is the
  paper's ``K * error``). Nearer the pivot than the floor ``f`` (:class:`Core`:
  at least so far that the steepest pull keeps the integrator stable),
  where the direction is ill-defined, the energy fades as
  ``(r / f)^2`` (a relative spring's by the product of its two pairs' fades),
  and the force is still its gradient: tangential ``K l error r / f^2`` and
  a pull toward the pivot of ``K l error^2 r / f^2``, bounded, nothing at the
  pivot. A field that is a gradient everywhere cannot keep a mass circling
  (friction takes energy out of every loop); a force held at its value
  inside the floor could, and a settle then never ended;
- distance spring: ``K (r - L)`` along the line between its masses;
- expansion: away from the explored centre, ``c`` (constant law) or ``c r``
  (proportional law).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from .placement import Resolved

EXPANSION_LAWS: dict[str, Callable[[float, np.ndarray], np.ndarray]] = {
    "constant": lambda c, r: c + 0.0 * r,  # N, the same for every mass
    "proportional": lambda c, r: c * r,  # N/m times m
}


def wrap(angle: np.ndarray) -> np.ndarray:
    """Angles wrapped to [-pi, pi)."""
    return (angle + np.pi) % (2 * np.pi) - np.pi


ANGLE_KINDS = {"global_angle": 1, "relative_angle": 2}  # kind codes of AngleSprings.of_arrays; 0: distance


@dataclass(frozen=True)
class Core:
    """Where an angle spring's energy fades round its pivot: within its floor, the largest of ``radius`` (m),
    ``share`` of its l, and ``per_root_torque`` (m per sqrt(N m/rad)) times sqrt(K l)."""

    radius: float
    share: float = 0.0
    per_root_torque: float = 0.0

    def floor(self, length: np.ndarray, torque: np.ndarray) -> np.ndarray:
        """The floor (m) of springs of ``length`` l (m) and ``torque`` K l (N m/rad)."""
        return np.maximum(np.maximum(self.radius, self.share * length), self.per_root_torque * np.sqrt(torque))


class AngleSprings:
    """Angle springs as one vectorised force field over ``n`` masses.

    ``ends``: per spring, the slots (indices into the position array) of its masses: (reference, figure)
    for a global spring, (a, vertex, b) for a relative one. Every spring acts along vectors ("pairs") from
    a tail to a head mass; its error is the angle of its second pair minus that of its first (a global
    spring's first pair is the x axis), wrapped. Each head is pushed along its pair's tangent and the tail
    takes the reaction.
    """

    def __init__(self, n: int, springs: Sequence[Resolved], ends: Sequence[Sequence[int]], lengths: Sequence[float],
                 *, core: Core) -> None:
        kind = np.array([ANGLE_KINDS.get(s.kind, 0) for s in springs], dtype=np.int8)
        slots = np.zeros((len(springs), 3), dtype=int)
        for i, x in enumerate(ends):
            slots[i, :len(x)] = x
        self._build(n, kind, slots, np.array([s.value for s in springs], dtype=float),
                    np.array([s.stiffness for s in springs], dtype=float), np.asarray(lengths, dtype=float),
                    core=core)

    @classmethod
    def of_arrays(cls, n: int, kind: np.ndarray, slots: np.ndarray, target: np.ndarray, stiffness: np.ndarray,
                  length: np.ndarray, *, core: Core) -> AngleSprings:
        """The same from arrays, one row a spring: ``kind`` 1 global, 2 relative, 0 not an angle spring
        (skipped); ``slots`` (rows of 3; a global spring uses the first 2); ``target`` rad; ``stiffness``
        N/rad; ``length`` l, m."""
        springs = cls.__new__(cls)
        springs._build(n, kind, slots, target, stiffness, length, core=core)
        return springs

    def _build(self, n: int, kind: np.ndarray, slots: np.ndarray, target: np.ndarray, stiffness: np.ndarray,
               length: np.ndarray, *, core: Core) -> None:
        self.n = n
        g, r = np.flatnonzero(kind == 1), np.flatnonzero(kind == 2)
        order = np.concatenate([g, r]).astype(int)
        n_g, n_r = len(g), len(r)
        # pairs: every global spring's (reference -> figure), then every relative spring's (vertex -> a), then
        # its (vertex -> b); the index n_pairs is the x axis (a global spring's first pair)
        slots = slots.reshape(-1, 3)
        self.heads = np.concatenate([slots[g, 1], slots[r, 0], slots[r, 2]]).astype(int)
        self.tails = np.concatenate([slots[g, 0], slots[r, 1], slots[r, 1]]).astype(int)
        n_pairs = len(self.heads)
        self.first = np.concatenate([np.full(n_g, n_pairs), n_g + np.arange(n_r)]).astype(int)
        self.second = np.concatenate([np.arange(n_g), n_g + n_r + np.arange(n_r)]).astype(int)
        pair_spring = np.concatenate([np.arange(n_g), n_g + np.arange(n_r), n_g + np.arange(n_r)]).astype(int)
        self.pair_spring = pair_spring
        self.turn = np.exp(-1j * target[order])  # a spring's error is the angle of second * conj(first) * turn
        torque = stiffness[order] * length[order]  # N m/rad
        # each pair's push per radian of error: the second pair is pushed back, the first forward
        self.gain = np.concatenate([-np.ones(n_g), np.ones(n_r), -np.ones(n_r)]) * torque[pair_spring]
        self.floor = core.floor(length[order], torque)[pair_spring]  # m, per pair
        self.ends = np.concatenate([self.heads, self.tails])
        self._d = np.ones(n_pairs + 1, dtype=complex)  # scratch: the pairs' vectors, then the x axis
        self.floor2 = self.floor ** 2
        self.per_floor2 = 1.0 / self.floor2
        self.pull_gain = np.abs(self.gain) / self.floor2  # N/m per rad^2: the pull toward the pivot is this e^2 r
        self._h = np.ones(n_pairs + 1)  # scratch: the pairs' fades, then the x axis's (1)
        # per pair, the other pair of its spring (the x axis for a global spring's figure)
        self.partner = np.concatenate([self.first[:n_g], self.second[n_g:], self.first[n_g:]]).astype(int)

    def __len__(self) -> int:
        return len(self.turn)

    def __call__(self, z: np.ndarray) -> np.ndarray:
        """Force (N, complex) on each of the ``n`` masses at complex positions ``z`` (m)."""
        if not len(self.heads):
            return np.zeros(self.n, dtype=complex)
        d = self._d[:-1]
        np.subtract(z[self.heads], z[self.tails], out=d)
        error = np.angle(self._d[self.second] * np.conj(self._d[self.first]) * self.turn)  # in (-pi, pi]
        r2 = d.real * d.real + d.imag * d.imag
        e = error[self.pair_spring]
        # E = K l e^2 h1 h2 / 2, h = (r / floor)^2 inside the floor and 1 outside, so per pair h / r^2 is
        # 1 / max(r^2, floor^2); the tangential force -dE / (r dtheta), and inside the floor the radial -dE / dr
        push = self.gain * e / np.maximum(r2, self.floor2) * (1j * d)
        inside = r2 < self.floor2
        if inside.any():  # the fades of the pairs' partners, and the pull toward the pivot
            fade = self._h[:-1]
            np.minimum(np.multiply(r2, self.per_floor2, out=fade), 1.0, out=fade)
            push -= (self.pull_gain * inside) * (e * e) * d
            push *= self._h[self.partner]
        both = np.concatenate([push, -push])  # heads pushed, tails take the reaction
        return np.bincount(self.ends, both.real, self.n) + 1j * np.bincount(self.ends, both.imag, self.n)


class NetForce:
    """The net force on a fixed list of masses from a fixed set of springs, evaluated as positions change.

    ``slots`` lists every mass it reads: ``names`` first, then every other end of ``springs``, in order of
    first appearance. ``lengths``: per spring, ``l`` (m) for an angle spring (ignored for distance springs);
    ``expand``: per name, whether the expansion force pushes it."""

    def __init__(self, names: Sequence[str], springs: Sequence[Resolved], lengths: Sequence[float], *,
                 expand: Sequence[bool], centre: complex | None, expansion: float, law: str, core: Core) -> None:
        slot = {name: i for i, name in enumerate(names)}
        for s in springs:
            for end in s.ends:
                slot.setdefault(end, len(slot))
        rows = np.zeros((len(springs), 3), dtype=int)
        for i, s in enumerate(springs):
            rows[i, :len(s.ends)] = [slot[e] for e in s.ends]
        self._build(names, list(slot), np.array([ANGLE_KINDS.get(s.kind, 0) for s in springs], dtype=np.int8), rows,
                    np.array([s.value for s in springs], dtype=float),
                    np.array([s.stiffness for s in springs], dtype=float), np.asarray(lengths, dtype=float),
                    expand=expand, centre=centre, expansion=expansion, law=law, core=core)

    @classmethod
    def of_arrays(cls, names: Sequence[str], slots: Sequence[str], kind: np.ndarray, rows: np.ndarray,
                  value: np.ndarray, stiffness: np.ndarray, length: np.ndarray, *, expand: Sequence[bool],
                  centre: complex | None, expansion: float, law: str, core: Core) -> NetForce:
        """The same from arrays, one row a spring: ``kind`` 0 distance (``value`` its natural length, m), 1
        global and 2 relative angle (``value`` rad, ``length`` l, m); ``rows`` of 3 indexing ``slots`` (distance
        and global springs use the first 2), whose first entries are ``names``."""
        net = cls.__new__(cls)
        net._build(names, slots, kind, rows, value, stiffness, length, expand=expand, centre=centre,
                   expansion=expansion, law=law, core=core)
        return net

    def _build(self, names: Sequence[str], slots: Sequence[str], kind: np.ndarray, rows: np.ndarray,
               value: np.ndarray, stiffness: np.ndarray, length: np.ndarray, *, expand: Sequence[bool],
               centre: complex | None, expansion: float, law: str, core: Core) -> None:
        self.slots = list(slots)
        self.n = len(names)
        rows = rows.reshape(-1, 3)
        self.angles = AngleSprings.of_arrays(len(self.slots), kind, rows, value, stiffness, length, core=core)
        distance = np.flatnonzero(kind == 0)
        self.a, self.b = rows[distance, 0], rows[distance, 1]
        self.stiffness, self.rest = stiffness[distance], value[distance]
        self.expand = np.asarray(expand, dtype=bool).reshape(-1)
        self.push = None if centre is None or expansion == 0.0 or not self.expand.any() else \
            (centre, EXPANSION_LAWS[law], expansion)

    def __call__(self, z: np.ndarray) -> np.ndarray:
        """Net force (N, complex) on each name, with every slot at complex position ``z`` (m)."""
        total = self.angles(z)
        if len(self.a):
            d = z[self.b] - z[self.a]
            r = np.abs(d)
            f = self.stiffness * (r - self.rest) * d / np.maximum(r, 1e-12)  # pulls the first end to the second
            total += np.bincount(self.a, f.real, len(z)) + 1j * np.bincount(self.a, f.imag, len(z))
            total -= np.bincount(self.b, f.real, len(z)) + 1j * np.bincount(self.b, f.imag, len(z))
        total = total[:self.n]
        if self.push is not None:
            centre, law, c = self.push
            mine = z[:self.n] - centre
            r = np.abs(mine)
            ok = self.expand & (r > 1e-12)
            total[ok] += law(c, r[ok]) * mine[ok] / r[ok]
        return total


def forces_on(names: Sequence[str], springs: Sequence[Resolved], where: Mapping[str, complex],
              lengths: Sequence[float], *, expand: Sequence[bool], centre: complex | None, expansion: float,
              law: str, core: Core) -> np.ndarray:
    """Net force (N, complex) on each of ``names`` from ``springs`` (with every end's position in ``where``)
    and, for those with ``expand`` true, the expansion force (see :class:`NetForce`)."""
    net = NetForce(names, springs, lengths, expand=expand, centre=centre, expansion=expansion, law=law, core=core)
    return net(np.array(list(map(where.__getitem__, net.slots)), dtype=complex))
