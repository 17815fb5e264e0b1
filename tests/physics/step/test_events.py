"""Events located inside the step: touchdown, lift-off and apex, checked against ballistic flight."""

import math

import numpy as np
import pytest

from ballenv.physics import Ground, Ring, Scene, simulate
from ballenv.physics.base.ring import inflated_radius

G = 9.81


@pytest.fixture(scope="module")
def bounce():
    ring = Ring(position=(0.0, 0.6))
    scene = Scene(rings=[ring], grounds=[Ground()], integrator="generalized_alpha", adaptive=True, dt=1e-3)
    return ring, simulate(scene, 0.9)


def test_events_come_in_physical_order(bounce):
    _, traj = bounce
    kinds = [kind for _, ring, kind in traj.events if ring == 0]
    assert kinds[:3] == ["touchdown", "liftoff", "apex"]
    times = [t for t, _, _ in traj.events]
    assert times == sorted(times)


def test_touchdown_time_matches_free_fall_of_the_inflated_ball(bounce):
    ring, traj = bounce
    t_touch = next(t for t, _, kind in traj.events if kind == "touchdown")
    fall = ring.position[1] - inflated_radius(ring)
    assert t_touch == pytest.approx(math.sqrt(2 * fall / G), abs=1e-5)


def test_apex_height_and_time_are_interpolated_exactly_for_ballistic_flight(bounce):
    _, traj = bounce
    t_lift = next(t for t, _, kind in traj.events if kind == "liftoff")
    t_apex, h_apex = traj.apexes()[0]
    # any recorded state between lift-off and apex predicts the apex of the free centre of mass
    k = np.searchsorted(traj.t, 0.5 * (t_lift + t_apex))
    centre = traj.x[k, 0].mean(axis=0)
    velocity = traj.v[k, 0].mean(axis=0)
    assert h_apex == pytest.approx(centre[1] + velocity[1] ** 2 / (2 * G), rel=1e-9)
    assert t_apex == pytest.approx(traj.t[k] + velocity[1] / G, abs=1e-9)
    # and it is not merely the highest recorded sample
    samples = traj.x[:, 0, :, 1].mean(axis=1)
    assert h_apex >= samples[traj.t > t_lift].max()
