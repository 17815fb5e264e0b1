"""The grounds' barrier: its derivatives against central differences on a tilted half-space, its
reach and its wall, and the straight motion's limit."""

import math

import numpy as np
import pytest

from ballenv.shell.touch import ground

TILTED = np.array([[0.6, 0.0, 0.8]])  # a unit normal
HEIGHT = np.array([0.01])


def one_vertex(d):
    """A vertex at distance ``d`` from the tilted plane."""
    return np.array([[0.3, -0.2, 0.0]]) + (d + HEIGHT[0] - 0.3 * 0.6) * TILTED


@pytest.mark.parametrize("d", [0.0002, 0.0005, 0.0009])
def test_barrier_derivatives_match_central_differences(d):
    dhat, kappa, eps = 1e-3, 1e4, 1e-9
    grad, blocks = np.zeros((1, 3)), np.zeros((1, 3, 3))
    x = one_vertex(d)
    assert ground.add_barrier(x, TILTED, HEIGHT, dhat, kappa, grad, blocks) == 1

    def energy(y):
        return ground.barrier_energy(y, TILTED, HEIGHT, dhat, kappa)

    def gradient(y):
        g = np.zeros((1, 3))
        ground.add_barrier(y, TILTED, HEIGHT, dhat, kappa, g, np.zeros((1, 3, 3)))
        return g[0]

    for a in range(3):
        e = np.zeros((1, 3))
        e[0, a] = eps
        assert grad[0, a] == pytest.approx((energy(x + e) - energy(x - e)) / (2 * eps), rel=1e-6, abs=1e-9)
        column = (gradient(x + e) - gradient(x - e)) / (2 * eps)
        assert np.allclose(blocks[0, :, a], column, rtol=1e-6, atol=1e-6 * np.abs(blocks).max())
    assert np.allclose(np.cross(grad[0], TILTED[0]), 0.0) and grad[0] @ TILTED[0] < 0  # along -n: pushes off
    lam = np.zeros((1, 1))
    ground.normal_forces(x, TILTED, HEIGHT, dhat, kappa, lam)
    assert lam[0, 0] == pytest.approx(-grad[0] @ TILTED[0])


def test_the_barrier_acts_only_within_dhat_and_walls_off_the_ground():
    assert ground.barrier_energy(one_vertex(0.0011), TILTED, HEIGHT, 1e-3, 1e4) == 0.0
    on_plane = np.array([[0.3, -0.2, 0.01]])
    assert ground.barrier_energy(on_plane, np.array([[0.0, 0.0, 1.0]]), HEIGHT, 1e-3, 1e4) == math.inf
    assert ground.barrier_energy(one_vertex(-0.005), TILTED, HEIGHT, 1e-3, 1e4) == math.inf
    assert ground.min_distance(one_vertex(0.004), TILTED, HEIGHT) == pytest.approx(0.004)


def test_a_straight_motion_stops_short_of_the_ground():
    flat, zero = np.array([[0.0, 0.0, 1.0]]), np.array([0.01])
    x = np.array([[0.0, 0.0, 0.02], [0.0, 0.0, 0.05]])
    dx = np.array([[0.0, 0.0, -0.1], [0.0, 0.0, 0.3]])
    alpha = ground.max_step(x, dx, flat, zero)
    assert alpha == pytest.approx(ground.CCD_SAFETY * 0.01 / 0.1)
    assert ground.max_step(x, np.abs(dx), flat, zero) == 1.0  # moving up: no limit
