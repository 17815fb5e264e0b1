"""Pressure (gas law), gravity and damping: forces, energies and exact Jacobians (central FD)."""

import numpy as np
import pytest

from ballenv.physics.base.geometry import polygon_area
from ballenv.physics.effects.damping import (
    DAMPING_CENTRE_OF_MASS,
    DAMPING_RIGID,
    damping_force,
    damping_jacobian,
)
from ballenv.physics.effects.gas import (
    gas_energy,
    gas_pressure,
    gas_pressure_slope,
    pressure_force,
    pressure_jacobian,
)
from ballenv.physics.effects.gravity import gravity_energy, gravity_force

from ..conftest import (
    DenseAssembler,
    deformed_ring,
    finite_difference_gradient,
    finite_difference_jacobian,
    relative_error,
)

WIDTH = 0.02
P_ATM = 101325.0


def _gas_constant(x, gauge, k):
    return (gauge + P_ATM) * polygon_area(x) ** k


def test_polygon_area_of_square():
    x = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 3.0], [0.0, 3.0]])
    assert polygon_area(x) == pytest.approx(6.0)
    assert polygon_area(x[::-1].copy()) == pytest.approx(-6.0)


@pytest.mark.parametrize("gauge", [30e3, -40e3])
@pytest.mark.parametrize("k", [0.0, 1.0, 1.4])
@pytest.mark.parametrize("n_nodes", [5, 64])
def test_pressure_force_is_minus_gas_energy_gradient(k, n_nodes, gauge):
    x = deformed_ring(n_nodes)
    c = _gas_constant(x, gauge, k) * 1.1

    def force(y):
        f = np.zeros_like(y)
        pressure_force(y, gas_pressure(polygon_area(y), c, k, P_ATM), WIDTH, f)
        return f

    grad = finite_difference_gradient(lambda y: gas_energy(polygon_area(y), c, k, P_ATM, WIDTH), x, 1e-7)
    assert relative_error(force(x), -grad) < 1e-6


@pytest.mark.parametrize("gauge", [30e3, -40e3])
@pytest.mark.parametrize("k", [0.0, 1.0, 1.4])
@pytest.mark.parametrize("n_nodes", [3, 8, 64])
def test_pressure_jacobian_with_gas_law_matches_finite_differences(k, n_nodes, gauge):
    x = deformed_ring(n_nodes, seed=3)
    c = _gas_constant(x, gauge, k) * 1.2

    def force(y):
        f = np.zeros_like(y)
        pressure_force(y, gas_pressure(polygon_area(y), c, k, P_ATM), WIDTH, f)
        return f

    asm = DenseAssembler(n_nodes)
    area = polygon_area(x)
    rank = pressure_jacobian(
        x,
        gas_pressure(area, c, k, P_ATM),
        gas_pressure_slope(area, c, k),
        WIDTH,
        1.0,
        asm.band,
        asm.pos,
        asm.u,
        asm.w,
        0,
    )
    assert rank == 1
    fd = finite_difference_jacobian(force, x, 1e-7)
    assert relative_error(asm.dense(rank), fd) < 1e-6


def test_gas_law_slope_matches_finite_difference():
    c, k, area = 5.0e3, 1.4, 0.03
    slope = gas_pressure_slope(area, c, k)
    fd = (gas_pressure(area + 1e-9, c, k, P_ATM) - gas_pressure(area - 1e-9, c, k, P_ATM)) / 2e-9
    assert slope == pytest.approx(fd, rel=1e-6)


@pytest.mark.parametrize("gauge", [30e3, -40e3])
def test_regulated_pressure_holds_its_value_whatever_the_area(gauge):
    """``k = 0``: ``p + p_atm = C`` at any area, no stiffness from the gas, potential ``-b p A``."""
    c = gauge + P_ATM
    for area in (0.01, 0.03, 0.05):
        assert gas_pressure(area, c, 0.0, P_ATM) == pytest.approx(gauge, rel=1e-12)
        assert gas_pressure_slope(area, c, 0.0) == 0.0
        assert gas_energy(area, c, 0.0, P_ATM, WIDTH) == pytest.approx(-WIDTH * gauge * area, rel=1e-9)


def test_gravity_force_and_energy():
    x = deformed_ring(16)
    g = np.array([0.3, -9.81])
    f = np.zeros_like(x)
    gravity_force(0.01, g, f)
    grad = finite_difference_gradient(lambda y: gravity_energy(y, 0.01, g), x, 1e-6)
    assert relative_error(f, -grad) < 1e-6


def _damping_force(mode, v_fixed=None, x_fixed=None):
    def f(y):
        out = np.zeros_like(y)
        xx = y if x_fixed is None else x_fixed
        vv = y if v_fixed is None else v_fixed
        damping_force(xx, vv, 0.004, 7.0, mode, out)
        return out

    return f


@pytest.mark.parametrize("mode", [DAMPING_RIGID, DAMPING_CENTRE_OF_MASS])
@pytest.mark.parametrize("n_nodes", [4, 32])
def test_damping_jacobians_match_finite_differences(mode, n_nodes):
    rng = np.random.default_rng(5)
    x = deformed_ring(n_nodes, seed=5)
    v = rng.standard_normal(x.shape)
    asm = DenseAssembler(n_nodes)
    rank = damping_jacobian(x, v, 0.004, 7.0, mode, 1.0, 0.0, asm.band, asm.pos, asm.u, asm.w, 0)
    fd_x = finite_difference_jacobian(_damping_force(mode, v_fixed=v), x, 1e-7)
    if mode == DAMPING_CENTRE_OF_MASS:
        assert np.max(np.abs(asm.dense(rank))) < 1e-15
        assert np.max(np.abs(fd_x)) < 1e-8
    else:
        assert relative_error(asm.dense(rank), fd_x) < 1e-6
    asm = DenseAssembler(n_nodes)
    rank = damping_jacobian(x, v, 0.004, 7.0, mode, 0.0, 1.0, asm.band, asm.pos, asm.u, asm.w, 0)
    fd_v = finite_difference_jacobian(_damping_force(mode, x_fixed=x), v, 1e-6)
    assert relative_error(asm.dense(rank), fd_v) < 1e-6


def test_rigid_damping_spares_flight_and_spin_and_cm_damping_brakes_spin():
    x = deformed_ring(32)
    centre = x.mean(axis=0)
    r = x - centre
    v = np.array([1.5, -2.0]) + 3.0 * np.stack([-r[:, 1], r[:, 0]], axis=1)
    assert np.max(np.abs(_damping_force(DAMPING_RIGID, v_fixed=v)(x))) < 1e-14
    torque_cm = _damping_force(DAMPING_CENTRE_OF_MASS, v_fixed=v)(x)
    assert np.sum(r[:, 0] * torque_cm[:, 1] - r[:, 1] * torque_cm[:, 0]) < 0.0
    assert np.max(np.abs(torque_cm.sum(axis=0))) < 1e-14
