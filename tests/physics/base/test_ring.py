"""A ring's geometry and material against their closed forms (``ballenv.physics.base.ring``)."""

import math

import numpy as np
import pytest

from ballenv.physics import Ring
from ballenv.physics.base import ring as geometry


@pytest.mark.parametrize("n", [3, 8, 64, 1000])
def test_the_rest_polygon_is_inscribed_in_the_circle(n):
    R = 0.12
    assert geometry.rest_edge_length(R, n) == pytest.approx(2 * R * math.sin(math.pi / n))
    assert geometry.rest_turning_angle(n) * n == pytest.approx(2 * math.pi)
    area = geometry.rest_area(R, n)
    assert area < math.pi * R**2
    if n == 1000:
        assert area == pytest.approx(math.pi * R**2, rel=1e-5)


def test_stiffnesses_and_masses_of_the_wall():
    ring = Ring(radius=0.1, n_nodes=32, youngs_modulus=8e6, thickness=3e-3, width=0.02, density=1200.0)
    assert geometry.stretching_stiffness(ring) == pytest.approx(8e6 * 0.02 * 3e-3)
    assert geometry.bending_stiffness(ring) == pytest.approx(8e6 * 0.02 * 3e-3**3 / 12)
    perimeter = 32 * geometry.rest_edge_length(0.1, 32)
    assert geometry.total_mass(ring) == pytest.approx(1200.0 * 0.02 * 3e-3 * perimeter)
    assert geometry.node_mass(ring) * 32 == pytest.approx(geometry.total_mass(ring))


@pytest.mark.parametrize("pressure", [-20e3, 0.0, 30e3])
def test_the_inflated_circle_balances_hoop_tension_and_gas(pressure):
    ring = Ring(radius=0.1, n_nodes=48, youngs_modulus=10e6, thickness=2e-3, width=0.02, pressure=pressure)
    r = geometry.inflated_radius(ring)
    ea, b, n = geometry.stretching_stiffness(ring), ring.width, ring.n_nodes
    # per node: 2 EA eps sin(pi / N) = p b r sin(2 pi / N), eps = r / R - 1
    assert 2 * ea * (r / 0.1 - 1) * math.sin(math.pi / n) == pytest.approx(
        pressure * b * r * math.sin(2 * math.pi / n), abs=1e-9
    )
    assert (r > 0.1) == (pressure > 0) and (r < 0.1) == (pressure < 0)


def test_burst_and_crush_pressures_stretch_by_100_and_compress_by_50_percent():
    args = (0.1, 32, 10e6, 2e-3)
    burst, crush = geometry.burst_pressure(*args), geometry.crush_pressure(*args)
    ring = Ring(radius=0.1, n_nodes=32, youngs_modulus=10e6, thickness=2e-3, width=0.02, pressure=burst)
    assert geometry.inflated_radius(ring) == pytest.approx(0.2)
    ring = Ring(radius=0.1, n_nodes=32, youngs_modulus=10e6, thickness=2e-3, width=0.02, pressure=crush)
    assert geometry.inflated_radius(ring) == pytest.approx(0.05)


def test_initial_nodes_move_rigidly():
    ring = Ring(n_nodes=20, position=(0.3, 1.0), velocity=(1.0, -2.0), angular_velocity=5.0)
    x, v = geometry.initial_nodes(ring)
    offset = x - np.array([0.3, 1.0])
    np.testing.assert_allclose(np.hypot(*offset.T), geometry.inflated_radius(ring))
    spin = 5.0 * np.stack([-offset[:, 1], offset[:, 0]], axis=1)
    np.testing.assert_allclose(v, np.array([1.0, -2.0]) + spin)
    np.testing.assert_allclose(x.mean(axis=0), [0.3, 1.0], atol=1e-15)
