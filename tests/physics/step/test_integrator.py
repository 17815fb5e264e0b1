"""The integrators against closed forms: their parameters, their free fall, their error estimate."""

import math

import numpy as np
import pytest

from ballenv.physics import Ring, Scene, simulate
from ballenv.physics.step.integrator import (
    build_solver,
    error_coefficient,
    error_exponent,
    error_start_weight,
    generalized_alpha_parameters,
)

G = 9.81


@pytest.mark.parametrize("rho", [0.0, 0.3, 0.9, 1.0])
def test_generalized_alpha_parameters_are_chung_hulberts(rho):
    alpha_m, alpha_f, beta, gamma = generalized_alpha_parameters(rho)
    assert alpha_m == pytest.approx((2 * rho - 1) / (rho + 1))
    assert alpha_f == pytest.approx(rho / (rho + 1))
    assert gamma == pytest.approx(0.5 - alpha_m + alpha_f)  # second order
    assert beta == pytest.approx(0.25 * (1 - alpha_m + alpha_f) ** 2)


def amplification(parameters, omega_h):
    """The matrix taking (x, h v, h^2 a) of ``x'' = -omega^2 x`` over one step of ``omega h``:
    ``x1 = x0 + h v0 + h^2 ((1/2 - beta) a0 + beta a1)``, ``v1 = v0 + h ((1 - gamma) a0 + gamma a1)``,
    ``(1 - alpha_m) a1 + alpha_m a0 = -omega^2 ((1 - alpha_f) x1 + alpha_f x0)`` (h = 1)."""
    alpha_m, alpha_f, beta, gamma = parameters
    w2 = omega_h**2
    lhs = np.array([[1.0, 0.0, -beta], [0.0, 1.0, -gamma], [w2 * (1 - alpha_f), 0.0, 1 - alpha_m]])
    rhs = np.array([[1.0, 1.0, 0.5 - beta], [0.0, 1.0, 1 - gamma], [-w2 * alpha_f, 0.0, -alpha_m]])
    return np.linalg.solve(lhs, rhs)


@pytest.mark.parametrize("rho", [0.0, 0.3, 0.9, 1.0])
def test_generalized_alpha_damps_unresolved_frequencies_to_rho_and_keeps_resolved_ones(rho):
    parameters = generalized_alpha_parameters(rho)
    high = np.abs(np.linalg.eigvals(amplification(parameters, 1e8))).max()
    assert high == pytest.approx(rho, abs=1e-5)
    low = np.abs(np.linalg.eigvals(amplification(parameters, 1e-3))).max()
    assert low == pytest.approx(1.0, abs=1e-6)


def test_rho_one_is_the_trapezoidal_rule():
    assert generalized_alpha_parameters(1.0) == pytest.approx((0.5, 0.5, 0.25, 0.5))


@pytest.mark.parametrize(
    ("integrator", "coefficient", "exponent", "start_weight"),
    [("backward_euler", 0.5, 0.5, 0.0), ("generalized_alpha", None, 1.0 / 3.0, 1.0)],
)
def test_local_error_constants(integrator, coefficient, exponent, start_weight):
    solver = build_solver(Scene(integrator=integrator, rho_infinity=0.5))
    expected = solver.beta - 1.0 / 6.0 if coefficient is None else coefficient
    assert error_coefficient(solver) == pytest.approx(expected)
    assert error_exponent(solver) == pytest.approx(exponent)  # 1 / (p + 1): p = 1, 2
    assert error_start_weight(solver) == start_weight


def _free_fall(integrator, dt, t_end):
    ring = Ring(n_nodes=16, position=(0.0, 1.0), velocity=(0.3, 2.0))
    scene = Scene(rings=[ring], gravity=G, adaptive=False, dt=dt, integrator=integrator, newton_tol=1e-12)
    traj = simulate(scene, t_end)
    centre = traj.centre_of_mass()[:, 0]
    exact = np.stack([0.3 * traj.t, 1.0 + 2.0 * traj.t - 0.5 * G * traj.t**2], axis=1)
    return centre, exact, traj.t


def test_generalized_alpha_falls_exactly():
    # a constant force is integrated exactly by a second-order Newmark scheme with a0 = F / m
    centre, exact, _ = _free_fall("generalized_alpha", 1e-3, 0.05)
    np.testing.assert_allclose(centre, exact, rtol=0, atol=1e-10)


def test_backward_euler_falls_with_its_first_order_error():
    # x_n = x0 + v0 t + g h^2 n (n + 1) / 2: below the parabola by g h t / 2, exactly
    dt, t_end = 1e-3, 0.05
    centre, exact, t = _free_fall("backward_euler", dt, t_end)
    np.testing.assert_allclose(centre[:, 0], exact[:, 0], rtol=0, atol=1e-10)
    np.testing.assert_allclose(exact[:, 1] - centre[:, 1], 0.5 * G * dt * t, rtol=1e-6, atol=1e-10)
    assert math.isclose(exact[-1, 1] - centre[-1, 1], 0.5 * G * dt * t_end, rel_tol=1e-6)
