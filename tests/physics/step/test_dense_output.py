"""Dense output: records at output times come from the accepted steps' interpolant, so recording
neither changes the steps nor the answer, and is exact where the interpolant is (a flight parabola)."""

from dataclasses import replace

import numpy as np
import pytest

from ballenv.physics import Ground, Ring, Scene, simulate
from ballenv.physics.base.ring import inflated_radius
from ballenv.physics.presets import with_fidelity

G = 9.81
RING = Ring(radius=0.1, n_nodes=32, pressure=30e3, position=(0.0, 0.5), velocity=(1.5, 2.0))


def bounce(**kw):
    """The ring bouncing on a floor at the balanced preset (error control)."""
    return replace(with_fidelity(Scene(rings=[RING], grounds=[Ground(friction=0.5)]), "balanced"), **kw)


@pytest.mark.parametrize("integrator", ["generalized_alpha", "backward_euler"])
def test_recording_takes_the_same_steps_and_ends_in_the_same_state(integrator):
    scene = bounce(integrator=integrator)
    plain = simulate(scene, 0.6)
    dense = simulate(scene, 0.6, output_dt=1e-3)
    for name in ("steps", "rejected_steps", "newton_iterations", "rejections"):
        assert getattr(dense.stats, name) == getattr(plain.stats, name), name
    assert plain.stats.steps < len(dense.t) == 601  # more records than steps
    np.testing.assert_array_equal(dense.x[-1], plain.x[-1])
    np.testing.assert_array_equal(dense.v[-1], plain.v[-1])
    assert dense.events == plain.events
    np.testing.assert_allclose(dense.t, np.arange(601) * 1e-3, rtol=0, atol=1e-12)


def test_a_flight_parabola_is_recorded_exactly():
    """A ring at rest on its inflated circle thrown upward: every node moves on the parabola
    ``x0 + v0 t - g t^2 / 2`` (the trapezoidal rule steps it exactly); the records between steps
    are on it to round-off, positions and velocities."""
    scene = Scene(rings=[RING], integrator="generalized_alpha", rho_infinity=1.0, dt=0.05)
    traj = simulate(scene, 0.5, output_dt=1e-3)
    assert traj.stats.steps == 10 and len(traj.t) == 501
    t = traj.t[:, None, None, None]
    lift = np.array([0.0, G])
    v0 = np.asarray(RING.velocity)
    np.testing.assert_allclose(traj.x, traj.x[0] + v0 * t - 0.5 * lift * t**2, rtol=0, atol=1e-11)
    np.testing.assert_allclose(traj.v, np.broadcast_to(v0 - lift * t, traj.v.shape), rtol=0, atol=1e-10)


def test_recorded_flight_follows_the_parabola_of_the_located_apex_and_no_node_is_below_the_ground():
    traj = simulate(bounce(), 1.2, output_dt=2e-3)
    (t_apex, y_apex), *_ = traj.apexes()
    com = traj.centre_of_mass()[:, 0, 1]
    flight = np.abs(traj.t - t_apex) < 0.15  # around the first apex, in flight
    assert flight.sum() > 100
    np.testing.assert_allclose(com[flight], y_apex - 0.5 * G * (traj.t[flight] - t_apex) ** 2, atol=1e-9)
    assert traj.x[..., 1].min() > -1e-9  # the records of touch-downs and rests stay above the ground
    assert com.min() < inflated_radius(RING)  # (it did bounce, squashed)
