"""The gas: volumes against closed forms, the volume's derivatives against central differences, and
the gas law's potential (dU/dV = -p, d2U/dV2 = gamma (p + p_atm) / V)."""

import numpy as np
import pytest

from ballenv.shell.scene import Shell
from ballenv.shell.skin.gas import (
    add_volume_hessians,
    gas_energy,
    gas_stiffness,
    gauge_pressure,
    volume,
    volume_gradient,
)
from ballenv.shell.skin.model import build_model

from ..conftest import assemble_dense, central_gradient, central_jacobian, relative_error, small_model

CUBE = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
CUBE_TRIANGLES = np.array(
    [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
     [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]
)  # fmt: skip


def test_the_volume_of_a_box_and_of_a_moved_box():
    scale = np.array([0.2, 0.3, 0.5])
    assert volume(CUBE * scale, CUBE_TRIANGLES) == pytest.approx(0.03, rel=1e-14)
    assert volume(CUBE * scale + (5.0, -3.0, 2.0), CUBE_TRIANGLES) == pytest.approx(0.03, rel=1e-12)


def test_the_volume_gradient_sums_to_zero_and_is_homogeneous_of_degree_three():
    g = np.zeros((8, 3))
    volume_gradient(CUBE, CUBE_TRIANGLES, g)
    assert g.sum(axis=0) == pytest.approx(np.zeros(3), abs=1e-15)  # translation leaves V unchanged
    assert np.einsum("ij,ij->", g, CUBE) == pytest.approx(3 * 1.0)  # Euler: x . dV/dx = 3 V


def test_volume_derivatives_match_central_differences():
    model, _, x = small_model()
    g = np.zeros_like(x)
    volume_gradient(x, model.triangles, g)
    assert relative_error(g, central_gradient(lambda y: volume(y, model.triangles), x)) < 1e-7
    mats = np.zeros((len(model.triangles), 9, 9))
    add_volume_hessians(x, model.triangles, 1.0, mats)

    def grad(y):
        out = np.zeros_like(y)
        volume_gradient(y, model.triangles, out)
        return out

    assert relative_error(assemble_dense(model.triangles, mats, len(x)), central_jacobian(grad, x)) < 1e-7


@pytest.mark.parametrize("gamma", [0.0, 1.0, 1.4])
def test_the_gas_potential_gives_the_pressure_and_its_stiffness(gamma):
    model = build_model(Shell(pressure=55e3), gas_exponent=gamma)
    v0 = model.rest_volume
    assert gauge_pressure(model, v0) == pytest.approx(55e3)
    assert gas_energy(model, v0) == 0.0
    v = 1.03 * v0
    dv = 1e-6 * v0
    assert (gas_energy(model, v + dv) - gas_energy(model, v - dv)) / (2 * dv) == pytest.approx(
        -gauge_pressure(model, v), rel=1e-7
    )
    expected = (101325.0 + 55e3) * (v0 / v) ** gamma
    assert gauge_pressure(model, v) + 101325.0 == pytest.approx(expected)
    assert gas_stiffness(model, v) == pytest.approx(gamma * expected / v)
