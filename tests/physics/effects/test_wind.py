"""Adding a force is one module and one registration line: a constant wind load (``wind.py``).

Checked as for the built-in effects: the total force with the wind is minus the gradient of the
total energy, the total Jacobian matches finite differences, a simulation follows the analytic
motion it implies, and a wind that is off changes no number of the registry's run.
"""

import numpy as np
import pytest

from ballenv.physics import Ring, Scene, Simulation, simulate
from ballenv.physics.build import build_model, build_workspace, scene_effects
from ballenv.physics.effects import EFFECTS
from ballenv.physics.effects.assembly import (
    effect_modules,
    energy_parts,
    field_name,
    ring_energy,
    ring_force,
    ring_jacobian,
)

from ..conftest import (
    DenseAssembler,
    deformed_ring,
    finite_difference_gradient,
    finite_difference_jacobian,
    relative_error,
)
from . import wind

WITH_WIND = EFFECTS + (wind,)  # the registration line (in the package: one line in effects.EFFECTS)


@pytest.fixture
def blowing():
    wind.LOAD[0] = (0.7, -0.2)
    yield
    wind.LOAD.clear()


def _ring_scene(**kw):
    return Scene(rings=[Ring(n_nodes=16, pressure=20e3, **kw)], damping=3.0, gravity=9.81)


def _model(scene):
    model = build_model(scene, WITH_WIND)
    return model, build_workspace(16, 1, WITH_WIND)


def test_wind_is_registered_with_its_own_parameters_and_energy_part(blowing):
    model, _ = _model(_ring_scene())
    assert energy_parts(WITH_WIND)[-1] == "wind"
    assert effect_modules(model.effect_parameters) == WITH_WIND
    np.testing.assert_array_equal(model.effect_parameters[field_name(len(EFFECTS), wind)], [[0.7, -0.2]])
    assert "wind" not in scene_effects(_ring_scene())  # scene_effects lists the registry's effects


def test_force_is_minus_energy_gradient_and_jacobian_is_exact(blowing):
    model, ws = _model(_ring_scene())
    x = deformed_ring(16, seed=3)
    v = np.zeros_like(x)  # damping has no potential and vanishes at rest
    parts = np.zeros(len(energy_parts(WITH_WIND)))

    def total_force(y):
        f = np.zeros_like(y)
        ring_force(model, 0, y, v, f)
        return f

    energy = finite_difference_gradient(lambda y: ring_energy(model, 0, y, v, parts), x, 1e-7)
    assert relative_error(total_force(x), -energy) < 1e-6
    rank = ring_jacobian(model, 0, x, v, 0.0, 1.0, 0.0, ws)  # c_M M - c_x dF/dx - c_v dF/dv
    dense = DenseAssembler(16)
    dense.band[:], dense.u[:], dense.w[:] = ws.band, ws.u, ws.w
    assert relative_error(-dense.dense(rank), finite_difference_jacobian(total_force, x, 1e-7)) < 1e-5


def test_wind_drives_the_centre_of_mass_as_newton_says(blowing):
    """A stiff ring in free fall under wind: the centre moves by ``(w / m + g) t^2 / 2`` exactly
    (internal forces cancel in the sum; the integrator is exact for constant acceleration)."""
    scene = Scene(rings=[Ring(n_nodes=16, pressure=None)], dt=1e-3)
    sim = Simulation(scene, effects=WITH_WIND)
    assert sim.advance(0.05)
    traj = sim.trajectory()
    m = build_model(scene).node_mass[0]
    expected = np.array([0.7 / m, -0.2 / m - 9.81]) * 0.05**2 / 2
    moved = traj.centre_of_mass()[-1, 0] - traj.centre_of_mass()[0, 0]
    np.testing.assert_allclose(moved, expected, rtol=1e-9)


def test_a_wind_that_is_off_changes_nothing():
    """Registered but off (no ring named in LOAD): the run equals the registry's to the last bit."""
    scene = _ring_scene()
    plain = simulate(scene, 0.02)
    sim = Simulation(scene, effects=WITH_WIND)
    assert sim.advance(0.02)
    windless = sim.trajectory()
    np.testing.assert_array_equal(windless.x, plain.x)
    np.testing.assert_array_equal(windless.v, plain.v)
    assert windless.stats.newton_iterations == plain.stats.newton_iterations
