"""Force laws for the angle springs and the expansion force, as one precomputed field.

Positions are complex numbers ``x + iy`` in metres, world frame; forces are
newtons, complex likewise.
Angle springs push tangentially with magnitude ``K * error`` (N, with the
error in radians; the "constant" law) or ``K * error * l / r`` (the "potential"
law: the gradient of ``K l error^2 / 2``, ``r`` the distance from the pivot),
faded linearly to zero within ``core`` metres of their pivot where the angle is
ill-defined; the reaction on the reference or vertex keeps each spring's net
force zero. The expansion force pushes masses away from the
centre of explored space, with a constant or a proportional law.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

_DENSE_LIMIT = 4_000  # masses x pairs up to which a dense incidence product beats bincounts (measured: 55 vs 60 us
# at 1,200, 350 vs 140 us at 7,500, 7.9 ms vs 0.15 ms at 270,000; the dense cost is quadratic in a cue's size)

EXPANSION_LAWS: dict[str, Callable[[float, np.ndarray], np.ndarray]] = {
    "constant": lambda c, r: c,  # N, the same for every mass
    "proportional": lambda c, r: c * r,  # N/m times m
}


ANGLE_LAWS = ("constant", "potential")  # K * error (N), or K * error * l / r (see the module's docstring)


def wrap(angle: np.ndarray) -> np.ndarray:
    """Angles wrapped to [-pi, pi)."""
    return (angle + np.pi) % (2 * np.pi) - np.pi


@dataclass(frozen=True)
class ForceField:
    """All per-step forces of a spring system other than its pymunk springs.

    Global angle springs hold the direction of ``g_fig`` seen from ``g_ref`` at
    ``g_angle``; relative angle springs hold the angle at ``r_vertex`` from ``r_a``
    to ``r_b`` (counter-clockwise) at ``r_angle``; ``expand`` masses are pushed
    away from ``centre``. Positions and forces are complex numbers ``x + iy``.

    Every angle spring acts along vectors ("pairs") from a tail to a head mass;
    a spring's error is the angle of its second pair minus that of its first
    (a global spring's first pair is the x axis). Each head is pushed along its
    pair's tangent and the tail takes the reaction, so one gather and one
    incidence product (bincounts for large systems) give every force.
    """

    n: int
    g_ref: np.ndarray
    g_fig: np.ndarray
    g_angle: np.ndarray
    g_k: np.ndarray
    r_a: np.ndarray
    r_vertex: np.ndarray
    r_b: np.ndarray
    r_angle: np.ndarray
    r_k: np.ndarray
    expand: np.ndarray
    centre: complex | None = None
    expansion: float = 0.0  # N or N/m, by law
    law: str = "constant"
    core: float = 0.5  # m
    angle_law: str = "constant"  # "constant": K * error (N); "potential": K * error * length / r
    g_length: np.ndarray | None = None  # m per global spring, for the potential law (None: 1 m)
    r_length: np.ndarray | None = None  # m per relative spring, likewise

    def __post_init__(self) -> None:
        if self.angle_law not in ANGLE_LAWS:
            raise ValueError(f"ForceField.angle_law must be one of {ANGLE_LAWS}, got {self.angle_law!r}")
        n_g, n_r = len(self.g_ref), len(self.r_a)
        heads = np.concatenate([self.g_fig, self.r_a, self.r_b]).astype(int)
        tails = np.concatenate([self.g_ref, self.r_vertex, self.r_vertex]).astype(int)
        n_pairs = len(heads)
        # Spring s measures angle(pair second[s]) - angle(pair first[s]); index n_pairs is the x axis.
        first = np.concatenate([np.full(n_g, n_pairs), n_g + np.arange(n_r)]).astype(int)
        second = np.concatenate([np.arange(n_g), n_g + n_r + np.arange(n_r)]).astype(int)
        # Each pair serves one spring: its second pair is pushed back (-1), its first forward (+1).
        pair_spring = np.concatenate([np.arange(n_g), n_g + np.arange(n_r), n_g + np.arange(n_r)]).astype(int)
        pair_sign = np.concatenate([-np.ones(n_g), np.ones(n_r), -np.ones(n_r)])
        incidence = None
        if self.n * n_pairs <= _DENSE_LIMIT:  # small systems: one matrix product beats two bincounts
            # complex, so the product needs no cast; each pair's sign and the quarter turn to its tangent folded in
            incidence = np.zeros((self.n, n_pairs), dtype=complex)
            np.add.at(incidence, (heads, np.arange(n_pairs)), 1.0)
            np.add.at(incidence, (tails, np.arange(n_pairs)), -1.0)
            incidence *= 1j * pair_sign
        fields = {"_heads": heads, "_tails": tails, "_ends": np.concatenate([heads, tails]), "_incidence": incidence,
                  "_first": first, "_second": second,
                  "_pair_spring": pair_spring, "_pair_sign": pair_sign,
                  "_target": np.concatenate([self.g_angle, self.r_angle]),
                  # scratch: pair angles (row 0) and fade gains (row 1), the extra last column being the x axis
                  # (angle 0, gain 1), so one gather takes both for every spring's pairs
                  "_angle_gain": np.vstack([np.zeros(n_pairs + 1), np.ones(n_pairs + 1)]),
                  "_ends_of_springs": np.concatenate([second, first]),
                  "_k": np.concatenate([self.g_k, self.r_k]),
                  # potential law: each pair's force is also scaled by its spring's length over the pair's length
                  "_pair_length": None if self.angle_law == "constant" else np.concatenate([
                      np.ones(n_g) if self.g_length is None else self.g_length,
                      np.ones(n_r) if self.r_length is None else self.r_length])[pair_spring]}
        for name, value in fields.items():
            object.__setattr__(self, name, value)

    def __call__(self, z: np.ndarray) -> np.ndarray:
        """Total force (N, complex) on each of the ``n`` masses at complex positions ``z`` (m)."""
        heads = self._heads  # type: ignore[attr-defined]
        if len(heads):
            d = z[heads] - z[self._tails]  # type: ignore[attr-defined]
            length = np.abs(d)
            angle_gain = self._angle_gain  # type: ignore[attr-defined]
            np.arctan2(d.imag, d.real, out=angle_gain[0, :-1])
            if self.core > 0:
                np.minimum(1.0, length / self.core, out=angle_gain[1, :-1])
            else:
                angle_gain[1, :-1] = length > 0
            n_springs = len(self._k)  # type: ignore[attr-defined]
            ends = angle_gain[:, self._ends_of_springs]  # type: ignore[attr-defined]
            second, first = ends[:, :n_springs], ends[:, n_springs:]
            error = wrap(second[0] - first[0] - self._target)  # type: ignore[attr-defined]
            spring = self._k * error * first[1] * second[1]  # type: ignore[attr-defined]
            per_pair = spring[self._pair_spring] / np.maximum(length, 1e-9)  # type: ignore[attr-defined]
            if self._pair_length is not None:  # type: ignore[attr-defined]
                per_pair *= self._pair_length / np.maximum(length, 1e-9)  # type: ignore[attr-defined]
            if self._incidence is not None:  # type: ignore[attr-defined]
                # the incidence holds each pair's sign and the turn 1j to its tangent
                forces = self._incidence @ (per_pair * d)  # type: ignore[attr-defined]
            else:
                scale = self._pair_sign * per_pair  # type: ignore[attr-defined]
                push = scale * 1j * d
                both = np.concatenate([push, -push])  # heads pushed, tails take the reaction
                ends = self._ends  # type: ignore[attr-defined]
                forces = np.bincount(ends, both.real, self.n) + 1j * np.bincount(ends, both.imag, self.n)
        else:
            forces = np.zeros(self.n, dtype=complex)
        if self.centre is not None and len(self.expand) and self.expansion != 0.0:
            d = z[self.expand] - self.centre
            length = np.abs(d)
            magnitude = EXPANSION_LAWS[self.law](self.expansion, length)
            if length.min() > 1e-9:
                forces[self.expand] += magnitude / length * d
            else:  # a mass at the centre has no direction to be pushed in
                ok = length > 1e-9
                forces[self.expand] += magnitude * ok / np.where(ok, length, 1.0) * d
        return forces
