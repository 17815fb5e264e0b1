"""Actuation spread over time (``drive.py``): gas ramps and spread impulses, stepped with the scene."""

import numpy as np
import pytest

from ballenv.physics import Ring, Scene
from ballenv.physics.actuation import rest_amount, rest_pressure_of
from ballenv.physics.effects.gas import gas_energy
from ballenv.physics.geometry import polygon_area
from ballenv.physics.layout import ENERGY_BUDGET
from ballenv.physics.model import build_model, build_workspace
from ballenv.physics.ring import total_mass
from ballenv.physics.simulation import Simulation

INTEGRATORS = ["backward_euler", "generalized_alpha"]
ALPHA_F = {"backward_euler": 0.0, "generalized_alpha": 0.9 / 1.9}  # Scene's rho_infinity = 0.9


def _falling_scene(integrator, adaptive, dt=1e-3):
    """A ring in the air under gravity, no ground: only gravity changes its momentum."""
    ring = Ring(n_nodes=32, pressure=30e3, position=(0.0, 1.0), velocity=(0.2, 0.0), angular_velocity=3.0)
    return Scene(rings=[ring], gravity=9.81, integrator=integrator, adaptive=adaptive, dt=dt)


def _momentum(sim):
    return sim.model.node_mass[0] * sim.state.v[0].sum(axis=0)


def _top_nodes(sim, count=5):
    return np.argsort(sim.state.x[0, :, 1])[-count:].astype(np.int64)


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("adaptive, dt", [(False, 1e-3), (False, 7e-4), (True, 2e-3)])
def test_spread_impulse_delivers_exactly_the_command_within_its_window(integrator, adaptive, dt):
    scene = _falling_scene(integrator, adaptive, dt)
    sim = Simulation(scene)
    assert sim.advance(0.0123)
    weight = total_mass(scene.rings[0]) * np.array([0.0, -9.81])
    impulse = np.array([0.02, -0.1])  # N s
    tau = 0.0041  # s, not a multiple of the step
    t0, p0 = sim.t, _momentum(sim)
    sim.apply_impulse(0, _top_nodes(sim), tuple(impulse), duration=tau)
    assert sim.advance(t0 + 0.5 * tau)
    part = _momentum(sim) - p0 - weight * (sim.t - t0)
    assert 0.0 < part[1] / impulse[1] < 1.0  # spread: half the window delivered part of it
    assert sim.advance(t0 + 0.03)  # steps land on the window's end by themselves
    delivered = _momentum(sim) - p0 - weight * (sim.t - t0)
    np.testing.assert_allclose(delivered, impulse, rtol=0.0, atol=1e-12 * np.abs(impulse).max())
    assert np.any(np.isclose(sim.trajectory().t, t0 + tau, rtol=0.0, atol=1e-12))
    stats = sim.stats()
    assert stats.rejected_steps == 0 or adaptive


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_spread_impulse_delivers_nothing_after_its_window(integrator):
    sim = Simulation(_falling_scene(integrator, adaptive=False), output_dt=None)
    assert sim.advance(0.005)
    weight = total_mass(sim.scene.rings[0]) * np.array([0.0, -9.81])
    t0, p0 = sim.t, _momentum(sim)
    tau = 0.0025
    sim.apply_impulse(0, _top_nodes(sim), (0.0, -0.08), duration=tau)
    assert sim.advance(t0 + 0.02)
    traj = sim.trajectory()
    m = sim.model.node_mass[0]
    after = traj.t >= t0 + tau - 1e-12
    assert after.sum() > 10
    momentum = m * traj.v[after, 0].sum(axis=1)  # (k, 2)
    gravity_only = momentum - weight * (traj.t[after, None] - t0) - p0
    np.testing.assert_allclose(gravity_only, np.tile([0.0, -0.08], (after.sum(), 1)), rtol=0, atol=1e-14)
    within = (traj.t > t0) & (traj.t < t0 + tau - 1e-12)
    partial = m * traj.v[within, 0].sum(axis=1)[:, 1] - weight[1] * (traj.t[within] - t0) - p0[1]
    np.testing.assert_allclose(partial, -0.08 * (traj.t[within] - t0) / tau, rtol=1e-12)  # constant rate


def _ramp_run(integrator, adaptive=False, dt=1e-3):
    scene = _falling_scene(integrator, adaptive, dt)
    sim = Simulation(scene, output_dt=None)
    assert sim.advance(0.0031)
    return sim


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_gas_ramp_holds_the_amount_of_each_steps_force_time_and_the_setpoint_at_its_end(integrator):
    sim = _ramp_run(integrator)
    t0, amount0 = sim.t, sim.model.gas_constant[0]
    duration = 0.0105
    sim.set_rest_pressure(0, 45e3, duration=duration)
    start = sim.trajectory().t.size - 1
    assert sim.model.gas_constant[0] == amount0  # nothing changes before a step
    assert sim.advance(t0 + duration)
    end_amount = sim.model.gas_constant[0]
    ws = build_workspace(32)
    model = build_model(sim.scene)
    assert end_amount == rest_amount(model, 0, 45e3, 32, ws)  # the setpoint's amount, to the bit
    # every step in between held the linear value at its force-evaluation time t_f = stop - alpha_f h
    traj = sim.trajectory()
    t = traj.t[start:]
    alpha_f = ALPHA_F[integrator]
    p_atm = sim.scene.atmospheric_pressure
    for k in range(1, t.size - 1):
        t_f = t[k] - alpha_f * (t[k] - t[k - 1])
        linear = amount0 + (t_f - t0) / duration * (end_amount - amount0)
        held = (traj.pressure[start + k, 0] + p_atm) * polygon_area(traj.x[start + k, 0])
        assert held == pytest.approx(linear, rel=1e-13)
    assert t[-1] == t0 + duration


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_energy_budget_is_credited_with_the_pump_work_of_each_step(integrator):
    """The budget rises by the pump's work: for each step, ``E(x_k; C_k) - E(x_k; C_held)`` at the
    step's start state ``x_k``, ``C_k`` the ramp's amount at the step's force time, and at the ramp's
    end ``E(x_end; C_1) - E(x_end; C_last)`` (the gas energy is the only part that depends on the
    amount; nothing else in this scene changes the budget)."""
    sim = _ramp_run(integrator)
    t0, amount0 = sim.t, sim.model.gas_constant[0]
    budget0 = sim.state.energy[0, ENERGY_BUDGET]
    duration = 0.0087
    sim.set_rest_pressure(0, 12e3, duration=duration)
    start = sim.trajectory().t.size - 1
    assert sim.advance(t0 + 0.02)
    assert sim.stats().rejected_steps == 0
    traj = sim.trajectory()
    t, x = traj.t[start:], traj.x[start:, 0]
    amount1 = rest_amount(build_model(sim.scene), 0, 12e3, 32, build_workspace(32))
    width, p_atm, alpha_f = sim.scene.rings[0].width, sim.scene.atmospheric_pressure, ALPHA_F[integrator]

    def gas(k, amount):
        return gas_energy(polygon_area(x[k]), amount, 1.0, p_atm, width)

    work, held = 0.0, amount0
    for k in range(t.size - 1):
        if t[k] >= t0 + duration:
            break
        t_f = t[k + 1] - alpha_f * (t[k + 1] - t[k])
        amount = amount0 + (t_f - t0) / duration * (amount1 - amount0)
        work += gas(k, amount) - gas(k, held)
        held = amount
    work += gas(k, amount1) - gas(k, held)  # the ramp's end: its setpoint, at the state there
    budget = sim.state.energy[0, ENERGY_BUDGET]
    assert abs(work) > 1.0  # J: the pump's work in the simulator's energy convention
    assert budget - budget0 == pytest.approx(work, rel=1e-12)


@pytest.mark.parametrize("pressure", [-20e3, 10e3, 45e3])
def test_rest_pressure_of_an_amount_inverts_the_rest_amount(pressure):
    scene = Scene(rings=[Ring(n_nodes=24, pressure=30e3)], gravity=0.0)
    model = build_model(scene)
    amount = rest_amount(model, 0, pressure, 24, build_workspace(24))
    for guess in (30e3, pressure + 5e3, pressure - 5e3):
        assert rest_pressure_of(model, 0, amount, guess, 24) == pytest.approx(pressure, rel=1e-10, abs=1e-6)
