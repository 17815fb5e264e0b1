"""The energy budget: an excess is taken from the deformation's kinetic energy keeping the linear
and angular momentum, else from the spin's keeping the linear momentum; a large one is refused;
shells that stepped jointly share a budget for good."""

import numpy as np
import pytest

from ballenv.shell import Scene, Shell
from ballenv.shell.simulation import build
from ballenv.shell.step.budget import ENERGY_GROWTH_TOL, Sharing, hold
from ballenv.shell.step.implicit import total_energy


@pytest.fixture(scope="module")
def shell_step():
    scene = Scene(shells=[Shell(subdivisions=1, position=(0, 0, 0))], gravity=0.0)
    return build(scene)[1][0]


def moments(st, x, v):
    m = st.problem.model.mass
    c = m @ x / m.sum()
    return m @ v, np.einsum("i,ij->j", m, np.cross(x - c, v))


def state(st, breathing):
    """The rest mesh spinning at 10 rad/s about z, moving at 1 m/s, breathing at ``breathing`` m/s."""
    x = st.problem.model.rest.copy()
    v = (
        np.cross([0.0, 0.0, 10.0], x)
        + np.array([1.0, 0.0, 0.0])
        + breathing * x / np.linalg.norm(x, axis=1)[:, None]
    )
    return x, v


def kinetic(st, v):
    return 0.5 * float(np.sum(st.problem.model.mass[:, None] * v * v))


@pytest.mark.parametrize("breathing", [0.5, 0.0])
def test_an_excess_is_removed_exactly_keeping_the_momentum(shell_step, breathing):
    st = shell_step
    x, v = state(st, breathing)
    energy = total_energy(st, x, v)
    p0, l0 = moments(st, x, v)
    excess = 1e-3 * kinetic(st, v - p0 / st.problem.model.mass.sum())
    assert hold([st], [x], [v], energy, energy - excess)
    assert total_energy(st, x, v) == pytest.approx(energy - excess, rel=1e-12)
    p1, l1 = moments(st, x, v)
    np.testing.assert_allclose(p1, p0, atol=1e-13)
    if breathing:  # paid by the breathing: the spin is kept
        np.testing.assert_allclose(l1, l0, rtol=1e-12, atol=1e-15)
    else:  # a rigid spin has nothing else to pay with: it slows
        assert 0.0 < l1[2] < l0[2]


def test_a_large_gain_is_refused_and_a_deficit_left_alone(shell_step):
    st = shell_step
    x, v = state(st, 0.5)
    energy, v0 = total_energy(st, x, v), v.copy()
    p = st.problem.model.mass @ v / st.problem.model.mass.sum()
    large = 2.0 * ENERGY_GROWTH_TOL * kinetic(st, v - p)
    assert not hold([st], [x], [v], energy, energy - large)
    assert hold([st], [x], [v], energy, energy + 1.0)
    np.testing.assert_array_equal(v, v0)


def test_two_shells_pay_an_excess_together_each_keeping_its_momentum(shell_step):
    st = shell_step
    (xa, va), (xb, vb) = state(st, 0.5), state(st, 0.2)
    xb = xb + 1.0
    energy = total_energy(st, xa, va) + total_energy(st, xb, vb)
    before = [moments(st, xa, va), moments(st, xb, vb)]
    assert hold([st, st], [xa, xb], [va, vb], energy, energy - 1e-4)
    assert total_energy(st, xa, va) + total_energy(st, xb, vb) == pytest.approx(energy - 1e-4, rel=1e-12)
    for (p0, l0), (p1, l1) in zip(before, [moments(st, xa, va), moments(st, xb, vb)], strict=True):
        np.testing.assert_allclose(p1, p0, atol=1e-13)
        np.testing.assert_allclose(l1, l0, rtol=1e-12, atol=1e-15)


def test_sharing_joins_sets_for_good():
    sharing = Sharing(4)
    assert sharing.sets() == [[0], [1], [2], [3]]
    sharing.join([1, 3])
    sharing.join([2])
    assert sharing.sets() == [[0], [1, 3], [2]]
    sharing.join([0, 3])
    assert sharing.sets() == [[0, 1, 3], [2]]
