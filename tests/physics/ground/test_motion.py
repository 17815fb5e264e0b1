"""Grounds that move: a conveyor belt, a rising floor and a vibrating plate, against rigid-body
theory, Galilean invariance and the balances of energy and momentum (``ground_motion.py``)."""

import math

import numpy as np
import pytest

from ballenv.physics import Ground, Ring, Scene, simulate
from ballenv.physics.base.layout import GROUND, SURFACE_NORMAL_ACCELERATION, SURFACE_OFFSET, SURFACE_VELOCITY
from ballenv.physics.base.ring import inflated_radius, total_mass
from ballenv.physics.ground.motion import ground_array, ground_surfaces, surface_array

N_NODES = 32
BALL = Ring(radius=0.1, n_nodes=N_NODES)
RADIUS = inflated_radius(BALL)  # m: the inflated circle's radius
MASS = total_mass(BALL)  # kg
G = 9.81
INTEGRATORS = ("generalized_alpha", "backward_euler")


def _resting_ball(ground, t_end, velocity=(0.0, 0.0), damping=50.0, output_dt=None, **scene_kw):
    """A ball set on ``ground`` (its lowest node 0.1 mm above it) moving at ``velocity`` (m/s)."""
    ring = Ring(radius=0.1, n_nodes=N_NODES, position=(0.0, RADIUS + 1e-4), velocity=velocity)
    kw = dict(adaptive=True, dt=1e-3, damping=damping)
    kw.update(scene_kw)
    return simulate(Scene(rings=[ring], grounds=[ground], **kw), t_end, output_dt=output_dt)


def _centre_velocity(traj):
    return traj.v[:, 0].mean(axis=1)  # (T, 2) m/s


def _spin(traj, k):
    """Angular velocity (rad/s) about the centre of mass, moment of inertia (kg m^2) and height of the
    centre of mass (m) of record ``k``."""
    x = traj.x[k, 0] - traj.x[k, 0].mean(axis=0)
    v = traj.v[k, 0] - traj.v[k, 0].mean(axis=0)
    m = MASS / N_NODES
    inertia = m * np.sum(x**2)
    momentum = m * np.sum(x[:, 0] * v[:, 1] - x[:, 1] * v[:, 0])
    return momentum / inertia, inertia, traj.x[k, 0, :, 1].mean()


def _surface_history(scene, t):
    """(T, SURFACE.size) the scene's first ground at the times ``t`` (s)."""
    model_grounds = ground_array(scene.grounds)
    out = np.zeros((len(t), surface_array(1).shape[1]))
    row = surface_array(len(scene.grounds))
    for k, tk in enumerate(t):
        ground_surfaces(model_grounds, tk, row)
        out[k] = row[0]
    return out


def _recorded_work(traj):
    """The work (J) of the recorded contact forces against the surface's motion, computed here from
    ``d(t)`` and ``w(t)`` (every step recorded): ``sum_k f_k . ds_k``,
    ``ds = (d(t_k) - d(t_k-1)) n + h (t . u) t``, and the sum of its steps' magnitudes."""
    s = _surface_history(traj.scene, traj.t)
    n = s[0, :2]
    tangent = np.array([-n[1], n[0]])
    f = traj.contact_force[1:, 0].sum(axis=1)  # (T - 1, 2) N
    h = np.diff(traj.t)
    slide = s[1:, SURFACE_VELOCITY : SURFACE_VELOCITY + 2] @ tangent
    steps = (f @ n) * np.diff(s[:, SURFACE_OFFSET]) + (f @ tangent) * slide * h
    return float(np.sum(steps)), float(np.sum(np.abs(steps)))


def _energy(traj):
    return traj.energy()["total"][:, 0]


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"velocity": (float("nan"), 0.0)}, "velocity"),
        ({"velocity": (2e3, 0.0)}, "velocity"),
        ({"velocity": (1.0, 0.0, 0.0)}, "velocity"),
        ({"velocity": "up"}, "velocity"),
        ({"amplitude": -1e-3, "frequency": 5.0}, "amplitude"),
        ({"amplitude": 1e3, "frequency": 5.0}, "amplitude"),
        ({"amplitude": float("inf"), "frequency": 5.0}, "amplitude"),
        ({"amplitude": 1e-3, "frequency": -5.0}, "frequency"),
        ({"amplitude": 1e-3, "frequency": 1e6}, "frequency"),
        ({"amplitude": 1e-3}, "frequency"),
        ({"frequency": True}, "frequency"),
    ],
)
def test_ground_rejects_invalid_motion_naming_the_field_value_and_range(kwargs, field):
    with pytest.raises(ValueError, match=rf"Ground\.{field} = .* is out of range: must be") as err:
        Ground(**kwargs)
    if kwargs == {"amplitude": 1e-3}:
        assert "Ground.frequency = 0.0" in str(err.value) and "(0, 100000] Hz" in str(err.value)
        assert "above 0 when amplitude > 0" in str(err.value)


def test_fixed_grounds_do_not_move_and_their_rows_stay_exact():
    fixed = Ground(angle=0.3, height=0.2, friction=0.4, x=-1.0)
    assert not fixed.moves and Ground(velocity=(0.0, 1e-3)).moves
    assert Ground(amplitude=1e-3, frequency=1.0).moves
    grounds = ground_array([fixed])
    assert grounds.shape == (1, GROUND.size)
    out = surface_array(1)
    ground_surfaces(grounds, 12.345, out)
    np.testing.assert_array_equal(out[0, :4], grounds[0, :4])  # normal, d0, mu: bit for bit
    assert np.all(out[0, SURFACE_VELOCITY:] == 0.0)


def test_surface_offset_velocity_and_acceleration_follow_the_prescribed_motion():
    a, amplitude, f, u = 0.2, 3e-3, 7.0, (0.4, -0.1)
    ground = Ground(angle=a, height=0.5, x=0.2, velocity=u, amplitude=amplitude, frequency=f)
    n = np.array([-math.sin(a), math.cos(a)])
    omega = 2 * math.pi * f
    out = surface_array(1)
    for t in (0.0, 0.013, 0.4):
        ground_surfaces(ground_array([ground]), t, out)
        d = n @ (0.2, 0.5) + (n @ u) * t + amplitude * math.sin(omega * t)
        w = np.array(u) + amplitude * omega * math.cos(omega * t) * n
        assert out[0, SURFACE_OFFSET] == pytest.approx(d, abs=1e-15)
        np.testing.assert_allclose(out[0, SURFACE_VELOCITY : SURFACE_VELOCITY + 2], w, rtol=0, atol=1e-14)
        a_n = -amplitude * omega**2 * math.sin(omega * t)
        assert out[0, SURFACE_NORMAL_ACCELERATION] == pytest.approx(a_n, abs=1e-12)
    # the offset's time derivative is the surface's normal velocity
    dt = 1e-7
    ground_surfaces(ground_array([ground]), 0.1 + dt, out)
    later = out[0, SURFACE_OFFSET]
    ground_surfaces(ground_array([ground]), 0.1 - dt, out)
    earlier = out[0, SURFACE_OFFSET]
    ground_surfaces(ground_array([ground]), 0.1, out)
    normal_velocity = n @ out[0, SURFACE_VELOCITY : SURFACE_VELOCITY + 2]
    assert (later - earlier) / (2 * dt) == pytest.approx(normal_velocity, rel=1e-6)


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_a_conveyor_belt_is_a_fixed_floor_seen_from_a_moving_frame(integrator):
    """Galilean invariance: a ball set at rest on a belt moving at u is a ball thrown at -u onto a
    fixed floor, shifted by u t: same steps, the same Newton iterations to one in a thousand (the
    friction Jacobian is as exact on the belt; the positions differ by round-off, so a solve that
    ends at its tolerance can take one more: measured 1858 against 1857 with backward Euler) and
    the same states."""
    u = 0.5
    kw = dict(integrator=integrator, output_dt=0.05)
    belt = _resting_ball(Ground(friction=0.5, velocity=(u, 0.0)), 0.6, **kw)
    floor = _resting_ball(Ground(friction=0.5), 0.6, velocity=(-u, 0.0), **kw)
    assert belt.stats.steps == floor.stats.steps and belt.stats.rejected_steps == floor.stats.rejected_steps
    iterations = belt.stats.newton_iterations, floor.stats.newton_iterations
    assert abs(iterations[0] - iterations[1]) <= 1e-3 * iterations[1]
    shift = np.zeros_like(belt.x)
    shift[..., 0] = u * belt.t[:, None, None]
    # to round-off (measured: 3e-15 m, 1.5e-12 m/s, 3e-12 N)
    np.testing.assert_allclose(belt.x - shift, floor.x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(belt.v - [u, 0.0], floor.v, rtol=0, atol=1e-9)
    np.testing.assert_allclose(belt.contact_force, floor.contact_force, rtol=0, atol=1e-9 * MASS * G)


def test_a_ball_on_a_conveyor_belt_rolls_with_it_and_creeps_up_to_its_speed():
    """Rigid-body theory of a ring set at rest on a belt moving at u: friction accelerates and spins
    it until its contact point moves with the belt (v + omega h = u, h the centre's height), after
    a slip time u / ((1 + M h^2 / I) mu g); the angular momentum about the contact line is kept
    meanwhile (in the belt's frame), so then v = u / (1 + M h^2 / I), about u / 2 for a thin ring.
    Rolling resistance (the wall's deformation damping as it rolls through its flattened patch) then
    slowly takes the rolling away in the belt's frame: v creeps up to u."""
    u = 0.5
    traj = _resting_ball(Ground(friction=0.5, velocity=(u, 0.0)), 6.0, output_dt=0.1)
    velocity = _centre_velocity(traj)[:, 0]
    k = int(np.argmin(np.abs(traj.t - 0.3)))
    omega, inertia, height = _spin(traj, k)
    assert velocity[k] + omega * height == pytest.approx(u, rel=0.03)  # rolling on the belt
    assert velocity[k] == pytest.approx(u / (1.0 + MASS * height**2 / inertia), rel=0.03)
    lag_early, lag_late = u - velocity[k], u - velocity[-1]
    assert 0.0 < lag_late < 0.8 * lag_early  # creeping up to the belt's speed
    assert np.all(velocity[k:] < u)


def test_a_frictionless_conveyor_belt_does_not_drag_the_ball():
    traj = _resting_ball(Ground(friction=0.0, velocity=(0.5, 0.0)), 1.0, output_dt=0.1)
    assert np.max(np.abs(_centre_velocity(traj)[:, 0])) < 1e-12
    assert abs(_spin(traj, -1)[0]) < 1e-9
    # a normal reaction does no work on a belt moving along itself (round-off: the budget's raises)
    assert abs(traj.stats.boundary_work) < 1e-9 * MASS * G * RADIUS


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_a_rising_floor_lifts_a_ball_resting_on_it(integrator):
    u = 0.2
    traj = _resting_ball(
        Ground(friction=0.5, velocity=(0.0, u)), 1.5, velocity=(0.0, u), damping=100.0, integrator=integrator,
        output_dt=0.01,
    )  # fmt: skip
    late = traj.t >= 0.5
    assert traj.stats.rejections["energy"] == 0
    assert _centre_velocity(traj)[late, 1].mean() == pytest.approx(u, rel=0.01)
    height = traj.centre_of_mass()[:, 0, 1] - u * traj.t  # above the rising floor
    assert np.max(np.abs(height - height[0])) < 2e-3
    assert np.min(traj.x[..., 1] - u * traj.t[:, None, None]) > -1e-6  # on or above the floor
    # its energy grows by the work the floor did (M g u t for the lift) less the damping's share
    work = traj.stats.boundary_work
    assert work == pytest.approx(MASS * G * u * traj.t[-1], rel=0.02)
    gain = _energy(traj)[-1] - _energy(traj)[0]
    assert 0.0 < work - gain < 0.02 * work


MOVING = {
    "belt": (Ground(friction=0.5, velocity=(0.5, 0.0)), (0.0, 0.0), 1.0),
    "rising": (Ground(friction=0.5, velocity=(0.0, 0.2)), (0.0, 0.2), 1.0),
    "vibrating": (Ground(friction=0.5, amplitude=5e-3, frequency=5.0), (0.0, 5e-3 * 2 * math.pi * 5.0), 1.0),
    "bouncing": (Ground(friction=0.5, amplitude=0.02, frequency=5.0), (0.0, 0.02 * 2 * math.pi * 5.0), 2.0),
}


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("name", MOVING)
def test_the_energy_budget_credits_the_work_of_a_moving_ground(name, integrator):
    """The guard never rejects a step for energy, the budget takes off at most 1e-3 of the grounds'
    work (the integrator's error of it; measured at most 3.4e-4), and the ring's energy stays
    within its start energy plus the credited work. Without arrivals (the belt, the rising floor)
    the credited work is the recorded contact forces' work along the surface's displacement to
    1e-3 (measured 5e-4); the vibrating plate (Gamma = 0.5) and the bouncing ball (Gamma = 2) also
    credit the impulses that put arriving nodes at rest on the moving plate."""
    ground, velocity, t_end = MOVING[name]
    traj = _resting_ball(ground, t_end, velocity=velocity, damping=20.0, integrator=integrator)
    stats = traj.stats
    work, gross = _recorded_work(traj)
    assert stats.rejections["energy"] == 0 and stats.energy_removed < 1e-3 * gross
    gain = _energy(traj)[-1] - _energy(traj)[0]
    assert gain <= stats.boundary_work  # the rest was dissipated (damping, friction, arrivals)
    if name in ("belt", "rising"):
        assert stats.boundary_work == pytest.approx(work, rel=1e-3)
    else:
        assert abs(stats.boundary_work - work) < 0.02 * gross  # the arrivals' share (measured 1.2 %)


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("name", ["belt", "rising"])
def test_momentum_changes_by_the_impulse_of_gravity_and_of_the_recorded_contact_forces(name, integrator):
    ground, velocity, t_end = MOVING[name]
    traj = _resting_ball(ground, t_end, velocity=velocity, integrator=integrator)
    m = MASS / N_NODES
    change = m * (traj.v[-1, 0].sum(axis=0) - traj.v[0, 0].sum(axis=0))
    contact = np.sum(traj.contact_force[1:, 0].sum(axis=1) * np.diff(traj.t)[:, None], axis=0)
    gravity = np.array([0.0, -G]) * MASS * (traj.t[-1] - traj.t[0])
    # to 2e-3 of the contact impulse (measured 2e-6 ... 6.5e-4: the velocity resets of nodes arriving
    # as the ball settles are not in the recorded forces)
    np.testing.assert_allclose(change, gravity + contact, rtol=0, atol=2e-3 * np.abs(contact).max())
