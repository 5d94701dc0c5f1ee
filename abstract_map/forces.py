"""Force laws for the angle springs and the expansion force, as one precomputed field.

Positions are an array ``(n, 2)`` in metres, world frame; forces are newtons.
Angle springs push tangentially with magnitude ``K * error`` (N, with the
error in radians), faded linearly to zero within ``core`` metres of their pivot
where the angle is ill-defined; the reaction on the reference or vertex keeps
each spring's net force zero. The expansion force pushes masses away from the
centre of explored space, with a constant or a proportional law.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

EXPANSION_LAWS: dict[str, Callable[[float, np.ndarray], np.ndarray]] = {
    "constant": lambda c, r: np.full_like(r, c),  # N
    "proportional": lambda c, r: c * r,  # N/m times m
}


def wrap(angle: np.ndarray) -> np.ndarray:
    """Angles wrapped to [-pi, pi)."""
    return (angle + np.pi) % (2 * np.pi) - np.pi


@dataclass(frozen=True)
class ForceField:
    """All per-step forces of a spring system other than its pymunk springs.

    Global angle springs hold the direction of ``g_fig`` seen from ``g_ref`` at
    ``g_angle``; relative angle springs hold the angle at ``r_vertex`` from ``r_a``
    to ``r_b`` (counter-clockwise) at ``r_angle``; ``expand`` masses are pushed
    away from ``centre``. Every angle spring acts along vectors ("pairs") from a
    tail to a head mass: the head is pushed along the pair's tangent and the tail
    takes the reaction, so one gather and one incidence product give every force.
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
    centre: np.ndarray | None = None
    expansion: float = 0.0  # N or N/m, by law
    law: str = "constant"
    core: float = 0.5  # m

    def __post_init__(self) -> None:
        n_g, n_r = len(self.g_ref), len(self.r_a)
        heads = np.concatenate([self.g_fig, np.ravel(np.column_stack([self.r_a, self.r_b]))]).astype(int)
        tails = np.concatenate([self.g_ref, np.repeat(self.r_vertex, 2)]).astype(int)
        incidence = np.zeros((self.n, len(heads)))
        np.add.at(incidence, (heads, np.arange(len(heads))), 1.0)
        np.add.at(incidence, (tails, np.arange(len(heads))), -1.0)
        object.__setattr__(self, "_heads", heads)
        object.__setattr__(self, "_tails", tails)
        object.__setattr__(self, "_incidence", incidence)
        object.__setattr__(self, "_n_g", n_g)
        object.__setattr__(self, "_n_r", n_r)

    def __call__(self, pos: np.ndarray) -> np.ndarray:
        """Total force (N) on each of the ``n`` masses at positions ``pos`` (m)."""
        n_g = self._n_g  # type: ignore[attr-defined]
        if len(self._heads):  # type: ignore[attr-defined]
            d = pos[self._heads] - pos[self._tails]  # type: ignore[attr-defined]
            length = np.hypot(d[:, 0], d[:, 1])
            angle = np.arctan2(d[:, 1], d[:, 0])
            gain = np.minimum(1.0, length / self.core) if self.core > 0 else (length > 1e-9) * 1.0
            scale = np.empty_like(length)
            scale[:n_g] = -self.g_k * wrap(angle[:n_g] - self.g_angle) * gain[:n_g]
            ang_a, ang_b = angle[n_g::2], angle[n_g + 1::2]
            w = self.r_k * wrap(ang_b - ang_a - self.r_angle) * gain[n_g::2] * gain[n_g + 1::2]
            scale[n_g::2] = w
            scale[n_g + 1::2] = -w
            scale /= np.maximum(length, 1e-9)  # tangent of d is (-dy, dx) / |d|
            push = d[:, ::-1] * scale[:, None]
            push[:, 0] *= -1.0
            forces = self._incidence @ push  # type: ignore[attr-defined]
        else:
            forces = np.zeros((self.n, 2))
        if self.centre is not None and len(self.expand) and self.expansion != 0.0:
            d = pos[self.expand] - self.centre
            length = np.hypot(d[:, 0], d[:, 1])
            ok = length > 1e-9
            magnitude = EXPANSION_LAWS[self.law](self.expansion, length) * ok
            forces[self.expand] += (magnitude / np.where(ok, length, 1.0))[:, None] * d
        return forces
