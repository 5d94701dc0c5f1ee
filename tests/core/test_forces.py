"""The forces outside pymunk's solver: angle springs (the potential law), and net forces on masses held still."""

from __future__ import annotations

import math

import numpy as np
import pytest

from abstract_map import forces
from abstract_map.forces import AngleSprings, Core, forces_on
from abstract_map.placement import Resolved


def angles(n, springs, ends, lengths, *, core=0.5, share=0.0):
    return AngleSprings(n, springs, ends, lengths, core=Core(core, share))


def test_global_angle_pushes_toward_its_direction_with_no_net_force():
    # reference at the origin, figure 3 m out along +x; the spring (l = 3 m) wants it at +y
    spring = Resolved("global_angle", ("r", "f"), math.pi / 2, 2.0)
    f = angles(2, [spring], [[0, 1]], [3.0])(np.array([0.0, 3.0 + 0j]))
    assert f[1].imag > 0 and abs(f[1]) == pytest.approx(2.0 * math.pi / 2)  # at r = l: the paper's K * error
    assert f.sum() == pytest.approx(0.0)


def test_relative_angle_turns_the_figure_and_balances():
    # the angle at the vertex from a (-x) to b wants pi; b sits at +y
    spring = Resolved("relative_angle", ("a", "v", "b"), math.pi, 1.0)
    pos = np.array([-2.0 + 0j, 0.0, 2.0j])
    f = angles(3, [spring], [[0, 1, 2]], [2.0])(pos)
    assert f[2].real > 0  # b is turned toward +x, away from a
    assert f.sum() == pytest.approx(0.0)
    assert (np.conj(pos - pos[1]) * f).imag.sum() == pytest.approx(0.0, abs=1e-12)  # no torque about the vertex


def _fade(r, floor):
    """The core's fade of the energy: s^2 at s = r / floor < 1, else 1."""
    return min(r / floor, 1.0) ** 2


def _energy(springs, ends, lengths, z, floor=0.5):
    """K l error^2 h / 2 summed over the springs: the potential law's energy, faded inside the core."""
    total = 0.0
    for s, e, length in zip(springs, ends, lengths):
        if s.kind == "global_angle":
            error = forces.wrap(np.angle(z[e[1]] - z[e[0]]) - s.value)
            fade = _fade(abs(z[e[1]] - z[e[0]]), floor)
        else:
            error = forces.wrap(np.angle(z[e[2]] - z[e[1]]) - np.angle(z[e[0]] - z[e[1]]) - s.value)
            fade = _fade(abs(z[e[0]] - z[e[1]]), floor) * _fade(abs(z[e[2]] - z[e[1]]), floor)
        total += 0.5 * s.stiffness * length * error ** 2 * fade
    return total


@pytest.mark.parametrize("z", [
    [0.0 + 0j, 3.0 + 1.0j, -2.0 + 0.5j, 1.0 - 2.0j],  # every pair outside the core
    [0.0 + 0j, 0.3 + 0.1j, -2.0 + 0.5j, 0.2 - 0.25j],  # some inside it
    [0.0 + 0j, -0.2 - 0.05j, 0.1 + 0.3j, -0.35 + 0.1j],  # every pair inside it, errors near pi
])
def test_the_angle_force_is_the_gradient_of_its_energy(z):
    springs = [Resolved("global_angle", ("0", "1"), 0.3, 1.0), Resolved("relative_angle", ("2", "0", "3"), 2.0, 0.5)]
    ends, lengths = [[0, 1], [2, 0, 3]], [4.0, 2.5]
    z = np.array(z)
    force = angles(4, springs, ends, lengths)(z)  # floor 0.5 m (core 0.5, share 0)
    h = 1e-7
    for i in range(4):
        for step in (h, 1j * h):
            ahead, behind = z.copy(), z.copy()
            ahead[i] += step
            behind[i] -= step
            slope = (_energy(springs, ends, lengths, ahead) - _energy(springs, ends, lengths, behind)) / (2 * h)
            assert slope == pytest.approx(-(force[i].real if step == h else force[i].imag), abs=1e-5)
    assert abs(force.sum()) < 1e-12


@pytest.mark.parametrize("core, share, floor", [(0.5, 0.0, 0.5), (0.5, 0.25, 1.0), (2.0, 0.25, 2.0)])
def test_inside_the_core_the_angle_force_fades_to_nothing_at_the_pivot(core, share, floor):
    spring = Resolved("global_angle", ("r", "f"), math.pi / 2, 1.0)  # K 1, l 4 m; the figure sits on +x: error -pi/2
    field = angles(2, [spring], [[0, 1]], [4.0], core=core, share=share)
    at = field(np.array([0.0, floor + 0j]))[1]
    just_out = field(np.array([0.0, floor * 1.001 + 0j]))[1]
    assert at == pytest.approx(1j * 4.0 * (math.pi / 2) / floor)  # the potential law's K l error / r, tangential
    assert just_out == pytest.approx(at, rel=2e-3)  # continuous where the core begins
    radii = np.linspace(1e-9, floor, 200)
    sizes = [abs(field(np.array([0.0, r + 0j]))[1]) for r in radii]
    # bounded (no place is flung round its pivot): tangential at most its value at the floor, and a pull toward
    # the pivot of at most K l error^2 / floor
    assert max(sizes) <= abs(at) + 4.0 * (math.pi / 2) ** 2 / floor
    assert sizes[0] < 1e-6  # and nothing at the pivot, where the direction means nothing


def test_net_force_on_a_mass_from_distance_angle_and_expansion():
    springs = [Resolved("distance", ("m", "#1"), 2.0, 0.5), Resolved("global_angle", ("#1", "m"), 0.0, 1.0)]
    where = {"m": 3.0 + 0j, "#1": 0j}
    f = forces_on(["m"], springs, where, [0.0, 3.0], expand=[True], centre=-1.0 + 0j, expansion=0.01,
                  law="constant", core=Core(0.5))
    assert f[0] == pytest.approx(-0.5 * 1.0 + 0.01)  # pulled back 1 m at 0.5 N/m, pushed out 0.01 N; on its angle
    f = forces_on(["m"], springs, {"m": 3.0j, "#1": 0j}, [0.0, 3.0], expand=[False], centre=None,
                  expansion=0.0, law="constant", core=Core(0.5))
    assert f[0].real == pytest.approx(1.0 * (math.pi / 2)) and f[0].imag == pytest.approx(-0.5)


@pytest.mark.parametrize("law, expected", [("constant", 0.01), ("proportional", 0.01 * 5.0)])
def test_expansion_laws(law, expected):
    f = forces_on(["m"], [], {"m": 3.0 + 4.0j}, [], expand=[True], centre=0j, expansion=0.01, law=law,
                  core=Core(0.5))
    assert abs(f[0]) == pytest.approx(expected)
    assert np.angle(f[0]) == pytest.approx(math.atan2(4, 3))


def test_expansion_spares_a_mass_at_the_centre():
    f = forces_on(["a", "b"], [], {"a": 1.0 + 1.0j, "b": 1.0 + 3.0j}, [], expand=[True, True], centre=1.0 + 1.0j,
                  expansion=0.01, law="constant", core=Core(0.5))
    assert f[0] == 0 and f[1] == pytest.approx(0.01j)


def test_a_core_reaches_as_far_as_its_steepest_pull_needs():
    core = Core(0.5, 0.25, 0.2 * math.pi)  # dt 0.2 s, mass 1 kg, w dt at most 1
    floors = core.floor(np.array([1.0, 5.3, 3.2, 8.0]), np.array([2.5, 0.5 * 5.3, 3.2, 0.1 * 8.0]))
    # a label (K 2.5, l 1): the pull; an arrow (K 0.5, l 5.3): l / 4; "past" (K 1, l 3.2): the pull; weak: l / 4
    assert floors == pytest.approx([0.2 * math.pi * math.sqrt(2.5), 5.3 / 4, 0.2 * math.pi * math.sqrt(3.2), 2.0])
    # at the floor the steepest pull (error pi) has w dt = 1
    k = math.pi ** 2 * 3.2 / floors[2] ** 2
    assert math.sqrt(k) * 0.2 == pytest.approx(1.0)
