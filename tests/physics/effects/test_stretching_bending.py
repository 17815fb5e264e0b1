"""Stretching and bending: forces are minus the energy gradient and Jacobians are exact (central FD)."""

import numpy as np
import pytest

from ballenv.physics.effects.bending import bend_energy, bend_force, bend_jacobian
from ballenv.physics.effects.stretching import stretch_energy, stretch_force, stretch_jacobian

from ..conftest import (
    DenseAssembler,
    deformed_ring,
    finite_difference_gradient,
    finite_difference_jacobian,
    relative_error,
)

EA = 400.0  # N
EI = 1.3e-4  # N m^2
RADIUS = 0.1


def _force(kernel, *params):
    def f(x):
        out = np.zeros_like(x)
        kernel(x, *params, out)
        return out

    return f


@pytest.mark.parametrize("n_nodes", [3, 8, 64])
@pytest.mark.parametrize("seed", [0, 1])
def test_stretch_force_is_minus_energy_gradient(n_nodes, seed):
    x = deformed_ring(n_nodes, seed=seed)
    l0 = 2 * RADIUS * np.sin(np.pi / n_nodes)
    grad = finite_difference_gradient(lambda y: stretch_energy(y, l0, EA), x, 1e-7)
    assert relative_error(_force(stretch_force, l0, EA)(x), -grad) < 1e-6


@pytest.mark.parametrize("n_nodes", [3, 8, 64])
@pytest.mark.parametrize("seed", [0, 1])
def test_stretch_jacobian_matches_finite_differences(n_nodes, seed):
    x = deformed_ring(n_nodes, seed=seed)
    l0 = 2 * RADIUS * np.sin(np.pi / n_nodes)
    asm = DenseAssembler(n_nodes)
    stretch_jacobian(x, l0, EA, 1.0, asm.band, asm.pos)
    fd = finite_difference_jacobian(_force(stretch_force, l0, EA), x, 1e-7)
    assert relative_error(asm.dense(), fd) < 1e-6


def _bent_ring(n_nodes, seed):
    """A deformed ring, its rest edge length (m) and rest turning angle (rad) of the regular polygon."""
    return deformed_ring(n_nodes, seed=seed), 2 * RADIUS * np.sin(np.pi / n_nodes), 2 * np.pi / n_nodes


@pytest.mark.parametrize("n_nodes", [3, 8, 64])
@pytest.mark.parametrize("seed", [0, 1])
def test_bend_force_is_minus_energy_gradient(n_nodes, seed):
    x, l0, phi0 = _bent_ring(n_nodes, seed)
    grad = finite_difference_gradient(lambda y: bend_energy(y, l0, EI, phi0), x, 1e-7)
    assert relative_error(_force(bend_force, l0, EI, phi0)(x), -grad) < 1e-6


@pytest.mark.parametrize("n_nodes", [3, 8, 64])
@pytest.mark.parametrize("seed", [0, 1])
def test_bend_jacobian_matches_finite_differences(n_nodes, seed):
    x, l0, phi0 = _bent_ring(n_nodes, seed)
    asm = DenseAssembler(n_nodes)
    bend_jacobian(x, l0, EI, phi0, 2.5, asm.band, asm.pos)
    fd = finite_difference_jacobian(_force(bend_force, l0, EI, phi0), x, 1e-7)
    assert relative_error(asm.dense(), 2.5 * fd) < 1e-6


def test_rest_shape_is_stress_free():
    n = 32
    theta = 2 * np.pi * np.arange(n) / n
    x = RADIUS * np.stack([np.cos(theta), np.sin(theta)], axis=1)
    l0 = 2 * RADIUS * np.sin(np.pi / n)
    f = np.zeros_like(x)
    stretch_force(x, l0, EA, f)
    bend_force(x, l0, EI, 2 * np.pi / n, f)
    assert np.max(np.abs(f)) < 1e-10 * EA
    assert stretch_energy(x, l0, EA) < 1e-20
    assert bend_energy(x, l0, EI, 2 * np.pi / n) < 1e-20
