"""Actuation between steps: gas amount and node impulses, against their definitions."""

import numpy as np
import pytest

from ballenv.physics import Ground, Ring, Scene
from ballenv.physics.base.layout import ENERGY, ENERGY_BUDGET, ENERGY_FREE, ENERGY_MOTION, ENERGY_TOTAL
from ballenv.physics.base.ring import inflated_radius, total_mass
from ballenv.physics.build import build_model, build_workspace, empty_state, initial_state
from ballenv.physics.effects.assembly import ring_force
from ballenv.physics.effects.gas import ring_pressure
from ballenv.physics.step.actuation import apply_impulse, rest_circle_radius, set_rest_pressure
from ballenv.physics.step.energy_budget import free_energy
from ballenv.physics.step.integrator import build_solver
from ballenv.physics.step.stepper import initial_state_values


def _ring_state(scene):
    model = build_model(scene)
    ws = build_workspace(scene.rings[0].n_nodes)
    state = empty_state(1, scene.rings[0].n_nodes)
    state.x[:], state.v[:] = initial_state(scene)
    return model, ws, state


@pytest.mark.parametrize("n_nodes", [16, 64])
@pytest.mark.parametrize("pressure", [5e3, 45e3])
def test_new_gas_amount_makes_its_inflated_circle_the_rest_state(n_nodes, pressure):
    scene = Scene(rings=[Ring(n_nodes=n_nodes, pressure=30e3)], gravity=0.0)
    model, ws, state = _ring_state(scene)
    set_rest_pressure(model, 0, pressure, state.x[0], state.v[0], state.energy[0], ws)
    radius = rest_circle_radius(model, 0, pressure, n_nodes)
    assert radius == pytest.approx(inflated_radius(Ring(n_nodes=n_nodes, pressure=pressure)), rel=1e-14)
    theta = 2 * np.pi * np.arange(n_nodes) / n_nodes
    circle = radius * np.stack([np.cos(theta), np.sin(theta)], axis=1)
    force = np.zeros_like(circle)
    ring_force(model, 0, circle, np.zeros_like(circle), force)
    hoop = pressure * scene.rings[0].width * 2 * np.pi * radius / n_nodes  # p b l per node
    assert np.abs(force).max() < 1e-9 * hoop  # wall tension balances the gas on the circle
    assert ring_pressure(model, 0, circle) == pytest.approx(pressure, rel=1e-12)
    out = np.zeros(ENERGY.size)
    free_energy(model, 0, circle, np.zeros_like(circle), ws, out)
    assert abs(out[ENERGY_FREE]) < 1e-12 * abs(out[ENERGY_TOTAL])  # the circle at rest has no free energy
    assert out[ENERGY_MOTION] == 0.0


def test_gas_change_updates_the_carried_energy_and_keeps_the_acceleration():
    scene = Scene(rings=[Ring(n_nodes=32, pressure=30e3)], grounds=[Ground()], gravity=9.81)
    model, ws, state = _ring_state(scene)
    initial_state_values(model, build_solver(scene), state, ws)
    before = state.energy[0].copy()
    acceleration = state.a[0].copy()
    assert before[ENERGY_BUDGET] == before[ENERGY_TOTAL] != 0.0  # the budget starts at the ring's energy
    set_rest_pressure(model, 0, 50e3, state.x[0], state.v[0], state.energy[0], ws)
    expected = np.zeros(ENERGY.size)
    free_energy(model, 0, state.x[0], state.v[0], ws, expected)
    for column in (ENERGY_TOTAL, ENERGY_FREE, ENERGY_MOTION):
        assert state.energy[0, column] == pytest.approx(expected[column], rel=1e-14, abs=1e-300)
    # the budget moves with the work of the actuation
    gained = expected[ENERGY_TOTAL] - before[ENERGY_TOTAL]
    assert state.energy[0, ENERGY_BUDGET] - before[ENERGY_BUDGET] == pytest.approx(gained, rel=1e-12)
    # the integrator's carried acceleration is not restarted (it is F / m of the old gas amount)
    np.testing.assert_array_equal(state.a[0], acceleration)
    force = np.zeros((32, 2))
    ring_force(model, 0, state.x[0], state.v[0], force)
    assert np.abs(force / model.node_mass[0] - acceleration).max() > 1.0  # m/s^2: the load changed
    assert state.energy[0, 1] > 0.0  # the old circle is now squeezed: stored energy


def test_impulse_changes_momentum_by_exactly_the_impulse():
    ring = Ring(n_nodes=32, velocity=(0.3, -1.0))
    model, ws, state = _ring_state(Scene(rings=[ring]))
    m = model.node_mass[0]
    before = m * state.v[0].sum(axis=0)
    nodes = np.array([3, 4, 5, 6, 7], dtype=np.int64)
    apply_impulse(model, 0, state.x[0], state.v[0], state.energy[0], ws, nodes, 5, 0.01, -0.2)
    after = m * state.v[0].sum(axis=0)
    np.testing.assert_allclose(after - before, [0.01, -0.2], rtol=1e-12)
    untouched = np.setdiff1d(np.arange(32), nodes)
    np.testing.assert_array_equal(state.v[0, untouched], np.array(ring.velocity) + 0 * state.v[0, untouched])
    assert total_mass(ring) == pytest.approx(32 * m)
