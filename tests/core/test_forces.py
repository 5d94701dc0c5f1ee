"""The angle-spring and expansion force laws."""

from __future__ import annotations

import math

import numpy as np
import pytest

from abstract_map import forces
from abstract_map.forces import ForceField


def field(n, *, g=(), r=(), expand=(), centre=None, expansion=0.0, law="constant"):
    g = np.array(g, dtype=float).reshape(-1, 4)
    r = np.array(r, dtype=float).reshape(-1, 5)
    return ForceField(n, g[:, 0].astype(int), g[:, 1].astype(int), g[:, 2], g[:, 3],
                      r[:, 0].astype(int), r[:, 1].astype(int), r[:, 2].astype(int), r[:, 3], r[:, 4],
                      np.array(expand, dtype=int), centre, expansion, law, 0.5)


def test_global_angle_pushes_toward_its_direction_with_no_net_force():
    # reference at the origin, figure at +x; the spring wants it at +y (90 degrees)
    f = field(2, g=[(0, 1, math.pi / 2, 2.0)])(np.array([0.0, 3.0 + 0j]))
    assert f[1].imag > 0 and abs(f[1]) == pytest.approx(2.0 * math.pi / 2)
    assert f.sum() == pytest.approx(0.0)


def test_relative_angle_turns_the_figure_and_balances():
    # angle at vertex 1 from a=0 to b=2 wants pi; b sits at 90 degrees
    pos = np.array([-2.0 + 0j, 0.0, 2.0j])
    f = field(3, r=[(0, 1, 2, math.pi, 1.0)])(pos)
    assert f[2].real > 0  # b is turned toward +x, away from a at -x
    assert f.sum() == pytest.approx(0.0)


def test_angle_force_fades_inside_the_core():
    near = field(2, g=[(0, 1, math.pi / 2, 1.0)])(np.array([0.0, 0.1 + 0j]))
    far = field(2, g=[(0, 1, math.pi / 2, 1.0)])(np.array([0.0, 1.0 + 0j]))
    assert abs(near[1]) == pytest.approx(abs(far[1]) * 0.1 / 0.5)


@pytest.mark.parametrize("law, expected", [("constant", 0.01), ("proportional", 0.01 * 5.0)])
def test_expansion_laws(law, expected):
    f = field(1, expand=[0], centre=0j, expansion=0.01, law=law)(np.array([3.0 + 4.0j]))
    assert abs(f[0]) == pytest.approx(expected)
    assert np.angle(f[0]) == pytest.approx(math.atan2(4, 3))


def test_dense_and_sparse_sums_agree(monkeypatch):
    rng = np.random.default_rng(0)
    pos = rng.normal(size=6) + 1j * rng.normal(size=6)
    spec = dict(g=[(0, 1, 0.3, 1.0), (2, 3, -2.0, 0.5)], r=[(4, 5, 0, math.pi, 1.0), (1, 2, 3, 0.5, 0.1)])
    dense = field(6, **spec)(pos)
    monkeypatch.setattr(forces, "_DENSE_LIMIT", 0)
    sparse = field(6, **spec)(pos)
    assert np.allclose(dense, sparse)


def test_expansion_spares_a_mass_at_the_centre():
    f = field(2, expand=[0, 1], centre=1.0 + 1.0j, expansion=0.01)(np.array([1.0 + 1.0j, 1.0 + 3.0j]))
    assert f[0] == 0 and f[1] == pytest.approx(0.01j)


def _energy(field_, z, lengths):
    """K l error^2 / 2 summed over a field's global and relative springs (the potential law's energy)."""
    d = lambda i, j: z[j] - z[i]  # noqa: E731
    total = 0.0
    for ref, fig, angle, k, length in zip(field_.g_ref, field_.g_fig, field_.g_angle, field_.g_k, lengths[0]):
        total += 0.5 * k * length * forces.wrap(np.angle(d(ref, fig)) - angle) ** 2
    for a, v, b, angle, k, length in zip(field_.r_a, field_.r_vertex, field_.r_b, field_.r_angle, field_.r_k,
                                         lengths[1]):
        total += 0.5 * k * length * forces.wrap(np.angle(d(v, b)) - np.angle(d(v, a)) - angle) ** 2
    return total


def test_potential_angle_law_is_the_gradient_of_its_energy_and_turns_nothing():
    g = np.array([(0, 1, 0.3, 1.0)])
    r = np.array([(2, 0, 3, 2.0, 0.5)])
    lengths = (np.array([4.0]), np.array([2.5]))
    f = ForceField(4, *g[:, :2].T.astype(int), g[:, 2], g[:, 3], *r[:, :3].T.astype(int), r[:, 3], r[:, 4],
                   np.array([], dtype=int), core=0.5, angle_law="potential", g_length=lengths[0],
                   r_length=lengths[1])
    z = np.array([0.0 + 0j, 3.0 + 1.0j, -2.0 + 0.5j, 1.0 - 2.0j])
    force = f(z)
    h = 1e-6
    for i in range(4):
        for step in (h, 1j * h):
            moved = z.copy()
            moved[i] += step
            slope = (_energy(f, moved, lengths) - _energy(f, z, lengths)) / h
            assert slope == pytest.approx(-(force[i].real if step == h else force[i].imag), abs=1e-4)
    assert abs(force.sum()) < 1e-12
    relative = ForceField(4, np.array([], dtype=int), np.array([], dtype=int), np.array([]), np.array([]),
                          *r[:, :3].T.astype(int), r[:, 3], r[:, 4], np.array([], dtype=int), core=0.5,
                          angle_law="potential", r_length=lengths[1])(z)
    torque = (np.conj(z - z[0]) * relative).imag.sum()  # about the vertex
    assert abs(torque) < 1e-12


def test_potential_angle_law_matches_the_constant_one_at_its_length():
    spec = dict(g=[(0, 1, math.pi / 2, 2.0)])
    constant = field(2, **spec)(np.array([0.0, 3.0 + 0j]))
    g = np.array(spec["g"])
    potential = ForceField(2, g[:, 0].astype(int), g[:, 1].astype(int), g[:, 2], g[:, 3],
                           *(np.array([], dtype=int),) * 3, np.array([]), np.array([]), np.array([], dtype=int),
                           core=0.5, angle_law="potential", g_length=np.array([3.0]))(np.array([0.0, 3.0 + 0j]))
    assert np.allclose(potential, constant)
