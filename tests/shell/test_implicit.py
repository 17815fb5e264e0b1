"""The implicit backward-Euler step: a free fall against its closed form, a drop onto the ground
(never through it, no energy growth, a bounce), and the incremental potential's gradient."""

import numpy as np
import pytest

from ballenv.shell import Shell, equilibrium
from ballenv.shell.implicit import (
    StepSettings,
    incremental,
    incremental_gradient,
    shell_kappa,
    step,
    step_problem,
    total_energy,
)
from ballenv.shell.model import build_model

from .conftest import central_gradient, relative_error

G = 9.81


@pytest.fixture(scope="module")
def ball():
    shell = Shell(subdivisions=2, pressure=20e3, position=(0, 0, 0.5))
    return shell, build_model(shell), equilibrium(shell).x


def centre(model, x):
    return model.mass @ x / model.mass.sum()


def test_a_free_fall_moves_the_centre_of_mass_exactly_as_backward_euler_and_keeps_the_shape(ball):
    shell, model, x_eq = ball
    settings = StepSettings(dt=1e-3, gravity=G)
    problem = step_problem(model, settings)
    x, v = x_eq.copy(), np.zeros_like(x_eq)
    for n in range(1, 41):
        x, v, _ = step(problem, settings, x, v)
        t = n * settings.dt
        drop = centre(model, x_eq)[2] - centre(model, x)[2]
        # backward Euler: z_n = z_0 - g dt^2 n (n + 1) / 2 = g t^2 / 2 + g t dt / 2
        assert drop == pytest.approx(G * settings.dt**2 * n * (n + 1) / 2, rel=1e-11)
        assert drop - G * t * t / 2 == pytest.approx(G * t * settings.dt / 2, rel=1e-9)
    assert np.abs((x - centre(model, x)) - (x_eq - centre(model, x_eq))).max() < 1e-12 * shell.radius
    assert np.allclose(v[:, 2], -G * 40 * settings.dt, rtol=1e-11, atol=0) and np.abs(v[:, :2]).max() < 1e-12


def test_a_drop_onto_the_ground_never_passes_it_never_gains_energy_and_bounces(ball):
    shell, model, x_eq = ball
    settings = StepSettings(dt=2e-4, gravity=G, ground_height=0.0, dhat=5e-4, kappa=shell_kappa(shell))
    problem = step_problem(model, settings)
    c = centre(model, x_eq)
    x = x_eq - c + (0, 0, np.linalg.norm(x_eq - c, axis=1).max() + 2e-3)  # 2 mm above the ground
    v = np.tile((0.0, 0.0, -2.0), (len(x), 1))
    energy = total_energy(problem, settings, x, v)
    lowest, touched = np.inf, False
    for _ in range(150):
        x, v, _ = step(problem, settings, x, v)
        new = total_energy(problem, settings, x, v)
        assert new <= energy + 1e-12 * abs(energy)  # backward Euler dissipates, never creates energy
        energy = new
        lowest = min(lowest, x[:, 2].min())
        touched |= x[:, 2].min() < settings.dhat
    assert touched and lowest > 0.0
    assert centre(model, v)[2] > 0.5  # on its way up again


def test_the_incremental_gradient_matches_central_differences(ball):
    shell, _, _ = ball
    small = Shell(subdivisions=1, pressure=20e3, position=(0, 0, 0))
    model = build_model(small)
    settings = StepSettings(dt=1e-3, ground_height=-small.radius - 1e-4, dhat=5e-4, kappa=shell_kappa(small))
    problem = step_problem(model, settings)
    rng = np.random.default_rng(2)
    x = model.rest + 1e-3 * rng.standard_normal(model.rest.shape)
    x[1, 2] = -small.radius - 0.5e-4  # the south pole within dhat of the ground
    target = x + 1e-3 * rng.standard_normal(x.shape)
    grad, diagonal = incremental_gradient(problem, settings, target, x)
    fd = central_gradient(lambda y: incremental(problem, settings, target, y), x, eps=1e-8)
    assert relative_error(grad, fd) < 1e-5
    assert np.all(diagonal >= model.mass[:, None] / settings.dt**2)  # the barrier stiffens only
