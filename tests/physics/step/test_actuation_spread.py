"""Actuation spread over time (``drive.py``): gas ramps and spread impulses, stepped with the scene."""

import numpy as np
import pytest

from ballenv.physics import Ring, Scene
from ballenv.physics.base.geometry import polygon_area
from ballenv.physics.base.layout import ENERGY_BUDGET
from ballenv.physics.base.ring import total_mass
from ballenv.physics.build import build_model, build_workspace
from ballenv.physics.effects.gas import gas_energy
from ballenv.physics.simulation import Simulation
from ballenv.physics.step.actuation import set_gas

INTEGRATORS = ["backward_euler", "generalized_alpha"]
ALPHA_F = {"backward_euler": 0.0, "generalized_alpha": 0.9 / 1.9}  # Scene's rho_infinity = 0.9


def _falling_scene(integrator, adaptive, dt=1e-3):
    """A ring in the air under gravity, no ground: only gravity changes its momentum."""
    ring = Ring(n_nodes=32, pressure=30e3, position=(0.0, 1.0), velocity=(0.2, 0.0), angular_velocity=3.0)
    return Scene(rings=[ring], gravity=9.81, integrator=integrator, adaptive=adaptive, dt=dt)


def _rest_gas(scene, pressure):
    """(amount (Pa m^2), rest energy (J)) of gauge pressure ``pressure`` (Pa) at rest in the scene's
    first ring (as ``set_rest_pressure`` sets them)."""
    model = build_model(scene)
    n = scene.rings[0].n_nodes
    set_gas(model, 0, pressure, n, build_workspace(n))
    return model.gas_constant[0], model.rest_energy[0]


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
    assert (end_amount, sim.model.rest_energy[0]) == _rest_gas(sim.scene, 45e3)  # the setpoint's, to the bit
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
    amount1 = _rest_gas(sim.scene, 12e3)[0]
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


@pytest.mark.parametrize(
    "p0, p1, bound",  # bound: of the rest energy's change over the ramp
    [(30e3, 34e3, 1e-6), (26e3, 22e3, 1e-6), (30e3, 40e3, 1e-5), (-20e3, 5e3, 1e-4), (10e3, 50e3, 5e-4)],
)
def test_the_rest_energy_follows_the_ramps_amount(p0, p1, bound):
    """Inside a ramp the ring's rest energy (which scales the energy guard's tolerance) is that of
    the inflated circle of the amount it holds (its exact rest pressure found by bisection, its rest
    energy as ``set_rest_pressure`` sets it), to the Hermite interpolant's error, fourth order in the
    amount's change: 2.6e-7 of the change for the env's 4 kPa steps (8 % of the amount), 2.6e-4 for
    10 to 50 kPa (2.2 times the amount)."""
    scene = Scene(rings=[Ring(n_nodes=32, pressure=p0)], gravity=0.0, integrator="backward_euler", dt=1e-3)
    sim = Simulation(scene, output_dt=None)
    sim.set_rest_pressure(0, p1, duration=0.01)
    for t in (0.002, 0.005, 0.007):
        assert sim.advance(t)
        amount, rest = sim.model.gas_constant[0], sim.model.rest_energy[0]
        low, high = min(p0, p1), max(p0, p1)
        for _ in range(200):
            mid = 0.5 * (low + high)
            low, high = (mid, high) if _rest_gas(scene, mid)[0] < amount else (low, mid)
        exact = _rest_gas(scene, 0.5 * (low + high))[1]
        change = abs(_rest_gas(scene, p1)[1] - _rest_gas(scene, p0)[1])
        assert abs(rest - exact) <= bound * change, (t, rest - exact, change)


def test_a_run_without_spread_actuation_has_no_drive_and_an_idle_drive_changes_no_bit():
    scene = _falling_scene("generalized_alpha", adaptive=False)
    plain = Simulation(scene, output_dt=None)
    assert plain.drive is None  # its step compiles none of drive.py
    driven = Simulation(scene, output_dt=None)
    for sim in (plain, driven):
        assert sim.advance(0.004)
    driven.apply_impulse(0, _top_nodes(driven), (0.0, 0.0), duration=1e-3)  # one grid step, nothing in it
    assert driven.drive is not None
    for sim in (plain, driven):
        assert sim.advance(0.02)
    a, b = plain.trajectory(), driven.trajectory()
    for name in ("t", "x", "v", "pressure"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    np.testing.assert_array_equal(plain.state.energy, driven.state.energy)


@pytest.mark.parametrize("duration", [-1e-3, float("nan"), 2e6])
def test_a_duration_out_of_range_names_the_argument_and_its_range(duration):
    sim = Simulation(_falling_scene("backward_euler", adaptive=False))
    message = r"is out of range: must be a finite number in \[0, 1e\+06\] s"
    with pytest.raises(ValueError, match=r"^Simulation\.set_rest_pressure\.duration = .*" + message):
        sim.set_rest_pressure(0, 40e3, duration=duration)
    with pytest.raises(ValueError, match=r"^Simulation\.apply_impulse\.duration = .*" + message):
        sim.apply_impulse(0, [0, 1], (0.0, -0.1), duration=duration)
