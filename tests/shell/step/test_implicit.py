"""The implicit step: its incremental potential's gradient against central differences, Newton's
direction against the gradient's change (the exact Hessian with barriers, friction, damping and
gas), free fall against its closed forms (generalized-alpha exact, backward Euler's lag), and the
invariants of a drop onto a ground (no vertex through it, no energy gained, the gas law held)."""

import numpy as np
import pytest

from ballenv.shell import Ground, Scene, Shell, simulate
from ballenv.shell.simulation import build
from ballenv.shell.skin.gas import volume
from ballenv.shell.skin.model import build_model
from ballenv.shell.step.implicit import (
    direction,
    incremental,
    incremental_gradient,
    total_energy,
)

from ..conftest import central_gradient, pressed_step, relative_error

G = 9.81


def centre(mass, x):
    return mass @ x / mass.sum()


@pytest.fixture(scope="module", params=["generalized_alpha", "backward_euler"])
def contact_step(request):
    """A small shell pressed on a tilted ground, moving and deforming, with damping and friction."""
    method, st, sp, x, _ = pressed_step(request.param, seed=3)
    assert (sp.lam > 0).sum() >= 2  # some vertices pressed on the ground
    return method, st, sp, x


def test_the_incremental_gradient_matches_central_differences(contact_step):
    method, st, sp, x = contact_step
    grad, _ = incremental_gradient(method, st, sp, x)
    fd = central_gradient(lambda y: incremental(method, st, sp, y), x, eps=1e-8)
    assert relative_error(grad, fd) < 1e-5


def test_newtons_direction_undoes_the_gradient_to_first_order(contact_step):
    method, st, sp, x = contact_step
    grad, blocks = incremental_gradient(method, st, sp, x)
    dx, _ = direction(st, sp, x, grad, blocks)
    eps = 1e-4
    plus = incremental_gradient(method, st, sp, x + eps * dx)[0]
    minus = incremental_gradient(method, st, sp, x - eps * dx)[0]
    change = (plus - minus) / (2 * eps)
    assert relative_error(change, -grad) < 1e-4  # H dx = -grad with the exact Hessian


@pytest.fixture(scope="module")
def ball():
    shell = Shell(subdivisions=2, pressure=20e3, position=(0, 0, 1.0))
    return shell, build_model(shell).mass


def test_free_fall_is_an_exact_parabola_for_generalized_alpha_and_lags_for_backward_euler(ball):
    shell, mass = ball
    dt, n = 1e-3, 40
    for integrator, lag in (("generalized_alpha", 0.0), ("backward_euler", 1.0)):
        # exact to round-off when Newton is asked to solve to round-off (newton_tol sets the solution)
        scene = Scene(shells=[shell], integrator=integrator, dt=dt, adaptive=False, newton_tol=1e-12)
        traj = simulate(scene, t_end=n * dt)
        drop = centre(mass, traj.x[0, 0])[2] - np.array([centre(mass, x)[2] for x in traj.x[:, 0]])
        t = traj.t
        # backward Euler: z_n = z_0 - g dt^2 n (n + 1) / 2 = g t^2 / 2 + g t dt / 2
        expected = G * t * t / 2 + lag * G * t * dt / 2
        assert np.abs(drop - expected).max() < 1e-11 * expected[-1]  # measured 1e-13 (GA), 7e-12 (BE)
        rel = traj.x[-1, 0] - centre(mass, traj.x[-1, 0])
        assert (
            np.abs(rel - (traj.x[0, 0] - centre(mass, traj.x[0, 0]))).max() < 1e-10 * shell.radius
        )  # the start is an equilibrium to 1e-10 E h l


@pytest.mark.parametrize("integrator", ["generalized_alpha", "backward_euler"])
def test_a_drop_never_passes_the_ground_never_gains_energy_and_holds_the_gas_law(ball, integrator):
    shell, mass = ball
    low = Shell(subdivisions=2, pressure=20e3, position=(0, 0, 0.132), velocity=(0.3, 0, -2.0))
    scene = Scene(
        shells=[low], grounds=[Ground(friction=0.3)], integrator=integrator, rho_infinity=1.0, dt=5e-4
    )
    traj = simulate(scene, t_end=0.04)
    assert traj.x[..., 2].min() > 0.0 and any(kind == "touchdown" for _, _, kind, _ in traj.events)
    _, (st,) = build(scene)
    energy = np.array([total_energy(st, x, v) for x, v in zip(traj.x[:, 0], traj.v[:, 0], strict=True)])
    # the rounding of the gas energy (p_abs V ~ 850 J, summed over 320 triangles) is ~1e-13 of
    # it; the tolerance 1e-10 p_abs V = 8.5e-8 J is 7e-8 of the kinetic energy at impact (1.2 J)
    rounding = 1e-10 * st.problem.model.absolute_pressure[0] * st.problem.model.rest_volume
    if integrator == "backward_euler":  # dissipative: the energy falls at every step
        assert np.all(np.diff(energy) <= rounding)
    else:  # the trapezoidal rule's energy oscillates within a step, never above its start
        assert energy.max() <= energy[0] + rounding
    assert energy[-1] < energy[0]
    vol = np.array([volume(x, st.problem.model.triangles) for x in traj.x[:, 0]])
    invariant = (traj.pressure[:, 0] + scene.atmospheric_pressure) * vol  # isothermal: gamma = 1
    assert np.abs(invariant / invariant[0] - 1).max() < 1e-13
    assert np.ptp(vol) > 1e-4 * vol[0]  # the ball was squeezed: the test is not vacuous
