"""Newton's iteration of one ring's implicit step: its converged step satisfies the integrator's
equation, to the tolerance it was asked for, and a step it cannot solve is reported failed."""

import numpy as np
import pytest

from ballenv.physics import Ring, Scene
from ballenv.physics.build import build, initial_state, simulation_workspace
from ballenv.physics.effects.assembly import ring_force
from ballenv.physics.ground.contact import FREE
from ballenv.physics.step.newton import FAILED, newton_ring

H = 2e-4  # s


def _squeezed_step(integrator, **changes):
    """One step of a ring squeezed by 3 % along y and moving, from rest of its carried acceleration:
    (scene, model, solver, x0, v0, a0, x1, v1, a1, corrections)."""
    scene = Scene(rings=[Ring(n_nodes=24, pressure=25e3)], gravity=9.81, integrator=integrator, **changes)
    model, solver, _, _ = build(scene)
    ws = simulation_workspace(scene, model, solver)
    x, v = initial_state(scene)
    centre = x[0].mean(axis=0)
    x0 = centre + (x[0] - centre) * np.array([1.0, 0.97])
    v0 = v[0] + np.array([0.4, -1.5])
    a0 = np.zeros_like(x0)
    ring_force(model, 0, x0, v0, a0)
    a0 /= model.node_mass[0]
    x1, v1, a1 = np.zeros_like(x0), np.zeros_like(x0), np.zeros_like(x0)
    active = np.full(x0.shape[0], FREE, dtype=np.int64)
    its = newton_ring(model, solver, 0, x0, v0, a0, H, x1, v1, a1, ws, active, None)
    return scene, model, solver, x0, v0, a0, x1, v1, a1, its


def _force(model, x, v):
    f = np.zeros_like(x)
    ring_force(model, 0, x, v, f)
    return f


def test_a_backward_euler_step_solves_m_dv_over_h_equals_f_at_its_end():
    scene, model, solver, x0, v0, _, x1, v1, _, its = _squeezed_step("backward_euler")
    assert 1 <= its < scene.newton_max_iter
    np.testing.assert_allclose(v1, (x1 - x0) / H, rtol=0, atol=1e-12)
    force = _force(model, x1, v1)
    residual = model.node_mass[0] * (v1 - v0) / H - force
    assert np.abs(residual).max() <= 10 * solver.newton_tol * np.abs(force).max()


def test_a_generalized_alpha_step_balances_the_forces_at_its_alpha_points():
    scene, model, solver, x0, v0, a0, x1, v1, a1, its = _squeezed_step("generalized_alpha", rho_infinity=0.5)
    assert 1 <= its < scene.newton_max_iter
    am, af, beta, gamma = solver.alpha_m, solver.alpha_f, solver.beta, solver.gamma
    np.testing.assert_allclose(x1, x0 + H * v0 + H * H * ((0.5 - beta) * a0 + beta * a1), rtol=0, atol=1e-13)
    np.testing.assert_allclose(v1, v0 + H * ((1 - gamma) * a0 + gamma * a1), rtol=0, atol=1e-10)
    force = _force(model, (1 - af) * x1 + af * x0, (1 - af) * v1 + af * v0)
    residual = model.node_mass[0] * ((1 - am) * a1 + am * a0) - force
    assert np.abs(residual).max() <= 10 * solver.newton_tol * np.abs(force).max()


def test_newton_converges_quadratically_so_a_tighter_tolerance_costs_an_iteration_or_two():
    loose = _squeezed_step("backward_euler", newton_tol=1e-4)[-1]
    tight = _squeezed_step("backward_euler", newton_tol=1e-12)[-1]
    assert loose <= tight <= loose + 2


def test_a_step_that_needs_more_iterations_than_allowed_fails():
    its = _squeezed_step("backward_euler", newton_tol=1e-12, newton_max_iter=1)[-1]
    assert its == FAILED


@pytest.mark.parametrize("integrator", ["backward_euler", "generalized_alpha"])
def test_a_ring_at_rest_in_its_inflated_shape_stays_there_without_gravity(integrator):
    scene = Scene(rings=[Ring(n_nodes=16)], gravity=0.0, integrator=integrator)
    model, solver, _, _ = build(scene)
    ws = simulation_workspace(scene, model, solver)
    x, v = initial_state(scene)
    x0, v0, a0 = x[0], v[0], np.zeros_like(x[0])
    x1, v1, a1 = np.zeros_like(x0), np.zeros_like(x0), np.zeros_like(x0)
    active = np.full(16, FREE, dtype=np.int64)
    its = newton_ring(model, solver, 0, x0, v0, a0, H, x1, v1, a1, ws, active, None)
    assert its >= 0
    np.testing.assert_allclose(x1, x0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(v1, 0.0, atol=1e-9)
