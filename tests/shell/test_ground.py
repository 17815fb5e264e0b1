"""The ground's barrier: its derivatives against central differences, its reach and its wall."""

import math

import numpy as np
import pytest

from ballenv.shell import ground


def one_vertex(z):
    return np.array([[0.3, -0.2, z]])


@pytest.mark.parametrize("z", [0.0102, 0.0105, 0.0109])
def test_barrier_derivatives_match_central_differences(z):
    height, dhat, kappa, eps = 0.01, 1e-3, 1e4, 1e-9
    grad, diagonal = np.zeros((1, 3)), np.zeros((1, 3))
    assert ground.add_barrier(one_vertex(z), height, dhat, kappa, grad, diagonal) == 1

    def energy(zz):
        return ground.barrier_energy(one_vertex(zz), height, dhat, kappa)

    def slope(zz):
        g = np.zeros((1, 3))
        ground.add_barrier(one_vertex(zz), height, dhat, kappa, g, np.zeros((1, 3)))
        return g[0, 2]

    assert grad[0, 2] == pytest.approx((energy(z + eps) - energy(z - eps)) / (2 * eps), rel=1e-6)
    assert diagonal[0, 2] == pytest.approx((slope(z + eps) - slope(z - eps)) / (2 * eps), rel=1e-6)
    assert grad[0, 2] < 0 and np.all(grad[0, :2] == 0)  # it pushes up only


def test_the_barrier_acts_only_within_dhat_and_walls_off_the_ground():
    assert ground.barrier_energy(one_vertex(0.0111), 0.01, 1e-3, 1e4) == 0.0
    assert ground.barrier_energy(one_vertex(0.01), 0.01, 1e-3, 1e4) == math.inf
    assert ground.barrier_energy(one_vertex(0.005), 0.01, 1e-3, 1e4) == math.inf


def test_a_straight_motion_stops_short_of_the_ground():
    x = np.array([[0.0, 0.0, 0.02], [0.0, 0.0, 0.05]])
    dx = np.array([[0.0, 0.0, -0.1], [0.0, 0.0, 0.3]])
    alpha = ground.max_step(x, dx, 0.01)
    assert alpha == pytest.approx(ground.CCD_SAFETY * 0.01 / 0.1)
    assert ground.max_step(x, np.abs(dx), 0.01) == 1.0  # moving up: no limit
