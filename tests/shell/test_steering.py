"""Simulation, the shell run driven piece by piece: the same steps as simulate, exact momentum of a
held force, the angular impulse of an off-centre one, the gas amount and its ramp, the budget's
credits, clear errors."""

import numpy as np
import pytest

from ballenv.shell import Ground, Scene, Shell, simulate
from ballenv.shell.presets import with_fidelity
from ballenv.shell.steering import Simulation

FREE = Scene(shells=(Shell(position=(0.0, 0.0, 1.0)),), gravity=9.81, newton_tol=1e-12, dt=2e-3)


def _momentum(sim):
    m = sim.run.steps[0].problem.model.mass
    c = m @ sim.x[0] / m.sum()
    return m @ sim.v[0], (m[:, None] * np.cross(sim.x[0] - c, sim.v[0])).sum(axis=0), c


def test_advanced_at_once_it_steps_as_simulate_bit_for_bit():
    scene = with_fidelity(Scene(shells=(Shell(position=(0.0, 0.0, 0.3)),), grounds=(Ground(),)), "fast")
    sim = Simulation(scene)
    sim.advance(0.2)
    traj = simulate(scene, 0.2)
    assert np.array_equal(sim.trajectory().x, traj.x) and np.array_equal(sim.trajectory().t, traj.t)


def test_a_held_force_changes_the_momentum_by_its_impulse_exactly():
    sim = Simulation(FREE, record=False)
    sim.advance(0.01)
    p0, _, _ = _momentum(sim)
    top = np.argsort(sim.x[0][:, 2])[-5:]
    impulse, duration = np.array([0.2, -0.1, -0.6]), 3e-3
    forces = np.zeros_like(sim.x[0])
    forces[top] = impulse / (len(top) * duration)
    sim.set_forces(0, forces)
    assert np.array_equal(sim.forces(0), forces)
    sim.advance(0.01 + duration)
    sim.set_forces(0, np.zeros_like(forces))
    p1, _, _ = _momentum(sim)
    weight = sim.run.steps[0].problem.model.mass.sum() * np.array([0.0, 0.0, -9.81])
    np.testing.assert_allclose(p1 - p0 - weight * duration, impulse, rtol=1e-9, atol=1e-9)


def test_an_off_centre_push_turns_the_ball_by_its_moment_r_x_j():
    sim = Simulation(FREE, record=False)
    _, l0, c = _momentum(sim)
    side = np.argsort(sim.x[0][:, 0])[-3:]  # the patch farthest along +x, pushed along +z
    impulse, duration = np.array([0.0, 0.0, 0.3]), 1e-3
    forces = np.zeros_like(sim.x[0])
    forces[side] = impulse / (len(side) * duration)
    arm = sim.x[0][side].mean(axis=0) - c
    sim.set_forces(0, forces)
    sim.advance(duration)
    sim.set_forces(0, np.zeros_like(forces))
    _, l1, _ = _momentum(sim)
    expected = np.cross(arm, impulse)
    assert np.linalg.norm(l1 - l0 - expected) < 0.02 * np.linalg.norm(expected)


def test_the_gas_amount_sets_the_pressure_and_its_ramp_lands_on_time():
    sim = Simulation(FREE, record=False)
    assert sim.rest_pressure(0) == pytest.approx(55e3)
    before = sim.gauge_pressure(0)
    sim.set_rest_pressure(0, 80e3)
    assert sim.gauge_pressure(0) > before + 20e3
    sim.ramp_rest_pressure(0, 40e3, 0.01)
    sim.advance(0.005)
    assert 40e3 < sim.rest_pressure(0) < 80e3
    sim.advance(0.02)
    assert sim.rest_pressure(0) == pytest.approx(40e3)


def test_settings_credit_the_energy_budget_by_the_energy_they_change():
    sim = Simulation(FREE, record=False)
    budget, energy = sim.run.budget[0], sim.energy(0)
    sim.set_rest_pressure(0, 90e3)
    assert sim.run.budget[0] - budget == pytest.approx(sim.energy(0) - energy, rel=1e-9, abs=1e-9)
    forces = np.full_like(sim.x[0], 0.01)
    budget, energy = sim.run.budget[0], sim.energy(0)
    sim.set_forces(0, forces)
    assert sim.run.budget[0] - budget == pytest.approx(sim.energy(0) - energy, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda s: s.advance(-1.0), "advance.t_end"),
        (lambda s: s.set_rest_pressure(0, -2e5), "set_rest_pressure.p0"),
        (lambda s: s.set_rest_pressure(3, 1e4), "Simulation.shell"),
        (lambda s: s.set_forces(0, np.zeros((2, 3))), "set_forces.forces"),
        (lambda s: s.ramp_rest_pressure(0, 1e4, 0.0), "ramp_rest_pressure.t1"),
    ],
)
def test_bad_settings_are_clear_errors(call, message):
    sim = Simulation(FREE, record=False)
    with pytest.raises(ValueError, match=message):
        call(sim)
