"""Ground contact: bounce against inflation pressure, no penetration or tunnelling, resting reaction,
slopes (rotational invariance), Coulomb friction."""

import math

import numpy as np
import pytest

from ballenv.physics import Ground, Ring, Scene, simulate
from ballenv.physics.base.ring import inflated_radius, total_mass

METHODS = ("mass_modification", "predictor_corrector")
INTEGRATORS = ("generalized_alpha", "backward_euler")
G = 9.81


def _drop(youngs_modulus=10e6, pressure=30e3, contact="mass_modification", impulse_tol=1e-3, **scene_kw):
    """First apex (m) of a ball dropped with its centre at 0.6 m, and the trajectory."""
    ring = Ring(youngs_modulus=youngs_modulus, pressure=pressure, position=(0.0, 0.6))
    kw = dict(integrator="generalized_alpha", adaptive=True, dt=1e-3, impulse_tol=impulse_tol)
    kw.update(scene_kw)
    scene = Scene(rings=[ring], grounds=[Ground()], contact=contact, **kw)
    traj = simulate(scene, 0.9)
    return traj.apexes()[0, 1], traj


@pytest.mark.parametrize("contact", METHODS)
@pytest.mark.parametrize("youngs_modulus", [10e6, 25e6])
def test_first_apex_rises_with_inflation_pressure_at_converged_settings(youngs_modulus, contact):
    apexes = []
    for pressure in (10e3, 30e3, 60e3):
        coarse, _ = _drop(youngs_modulus, pressure, contact, impulse_tol=1e-3)
        fine, traj = _drop(youngs_modulus, pressure, contact, impulse_tol=5e-4)
        # converged: halving the impulse tolerance moves the apex by far less than the trend
        assert abs(coarse - fine) < 3e-3 * fine
        assert np.min(traj.x[..., 1]) >= (-1e-6 if contact == "mass_modification" else -1e-12)
        apexes.append(fine)
    assert apexes[0] < apexes[1] < apexes[2]
    assert apexes[2] - apexes[0] > 0.05 * apexes[0]


def test_both_contact_methods_agree_on_the_converged_first_apex():
    for pressure in (10e3, 60e3):
        mm, _ = _drop(pressure=pressure, contact="mass_modification", impulse_tol=5e-4)
        pc, _ = _drop(pressure=pressure, contact="predictor_corrector", impulse_tol=5e-4)
        assert pc == pytest.approx(mm, rel=1e-2)


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("contact", METHODS)
def test_30_m_per_s_impact_neither_penetrates_nor_tunnels(contact, integrator):
    ring = Ring(position=(0.0, 0.3), velocity=(0.0, -30.0))
    scene = Scene(
        rings=[ring], grounds=[Ground()], contact=contact, integrator=integrator, adaptive=True, dt=1e-3
    )
    traj = simulate(scene, 0.05)
    assert np.all(np.isfinite(traj.x))
    assert np.min(traj.x[..., 1]) >= (-1e-6 if contact == "mass_modification" else -1e-12)
    kinds = [kind for _, _, kind in traj.events]
    assert kinds[:2] == ["touchdown", "liftoff"]
    assert traj.v[-1, 0, :, 1].mean() > 5.0  # it bounced back up


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("contact", METHODS)
def test_resting_ball_ground_reaction_equals_its_weight(contact, integrator):
    ring = Ring(position=(0.0, 0.12))
    scene = Scene(
        rings=[ring], grounds=[Ground(friction=0.5)], contact=contact, integrator=integrator,
        damping=60.0, dt=1e-3, adaptive=True,
    )  # fmt: skip
    traj = simulate(scene, 3.0, output_dt=0.05)  # the ball rocks on its contact patch for a while
    weight = total_mass(ring) * G
    reaction = traj.contact_force[-1, 0].sum(axis=0)
    assert reaction[1] == pytest.approx(weight, rel=5e-3)
    assert abs(reaction[0]) < 1e-3 * weight
    assert np.max(np.abs(traj.v[-1])) < 1e-3


def _rotation(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


@pytest.mark.parametrize("contact", METHODS)
def test_a_slope_equals_flat_ground_with_gravity_rotated(contact):
    angle = 0.4
    ring = Ring(position=(0.0, 0.0), angular_velocity=3.0)
    theta = 2 * np.pi * np.arange(ring.n_nodes) / ring.n_nodes
    circle = inflated_radius(ring) * np.stack([np.cos(theta), np.sin(theta)], axis=1)
    # sloped scene: ball 0.3 m above a slope through the origin, true gravity
    normal = np.array([-math.sin(angle), math.cos(angle)])
    x_slope = circle + 0.3 * normal
    v_slope = np.tile([0.5, -1.0], (ring.n_nodes, 1))
    common = dict(contact=contact, dt=2e-4, impulse_tol=2e-3, adaptive=True)
    sloped = Scene(rings=[ring], grounds=[Ground(angle=angle, friction=0.4)], gravity=G, **common)
    # flat scene: the same, seen in the slope's frame (rotated by -angle)
    back = _rotation(-angle)
    g_flat = back @ np.array([0.0, -G])
    flat = Scene(rings=[ring], grounds=[Ground(friction=0.4)], gravity=tuple(g_flat), **common)
    traj_s = simulate(sloped, 0.4, x0=x_slope, v0=v_slope, output_dt=0.01)
    traj_f = simulate(flat, 0.4, x0=x_slope @ back.T, v0=v_slope @ back.T, output_dt=0.01)
    assert any(kind == "touchdown" for _, _, kind in traj_s.events)
    rotated_back = traj_f.x @ _rotation(angle).T
    assert np.max(np.abs(rotated_back - traj_s.x)) < 1e-8


@pytest.mark.parametrize("contact", METHODS)
def test_on_a_slope_a_ring_slides_at_g_sin_a_without_friction_and_rolls_at_half_with_it(contact):
    angle = 0.2
    ring = Ring(pressure=60e3, position=(0.0, 0.0))
    radius = inflated_radius(ring)
    theta = 2 * np.pi * np.arange(ring.n_nodes) / ring.n_nodes
    normal = np.array([-math.sin(angle), math.cos(angle)])
    downhill = -np.array([math.cos(angle), math.sin(angle)])
    x0 = radius * np.stack([np.cos(theta), np.sin(theta)], axis=1) + (radius + 1e-9) * normal
    expected = {0.0: G * math.sin(angle), 1.0: G * math.sin(angle) / 2}  # slide; roll (a hoop)
    for mu, acceleration in expected.items():
        scene = Scene(
            rings=[ring], grounds=[Ground(angle=angle, friction=mu)], contact=contact, damping=50.0,
            dt=1e-3, adaptive=True, impulse_tol=1e-3,
        )  # fmt: skip
        traj = simulate(scene, 0.5, x0=x0, output_dt=0.01)
        s = traj.centre_of_mass()[:, 0] @ downhill
        fitted = 2 * np.polyfit(traj.t[10:], s[10:], 2)[0]
        touching = np.any(traj.contact_force[-1, 0] != 0, axis=1)
        slip = traj.v[-1, 0, touching] @ downhill
        if mu == 0.0:
            assert fitted == pytest.approx(acceleration, rel=1e-6)
        else:  # rolling without slipping; the squashed contact patch costs a little
            assert fitted == pytest.approx(acceleration, rel=3e-2)
            assert np.max(np.abs(slip)) < 2e-3  # m/s: sticking nodes barely creep


def _spin(x, v):
    """Angular velocity (rad/s, counter-clockwise) of equal-mass nodes about their centre."""
    r = x - x.mean(axis=0)
    u = v - v.mean(axis=0)
    return float(np.sum(r[:, 0] * u[:, 1] - r[:, 1] * u[:, 0]) / np.sum(r**2))


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_frictionless_bounce_keeps_horizontal_velocity(integrator):
    ring = Ring(position=(0.0, 0.3), velocity=(2.0, 0.0))
    scene = Scene(rings=[ring], grounds=[Ground(friction=0.0)], integrator=integrator, dt=1e-3)
    traj = simulate(scene, 0.5)
    assert any(kind == "liftoff" for _, _, kind in traj.events)
    vx = traj.v[:, 0, :, 0].mean(axis=1)
    assert np.max(np.abs(vx - 2.0)) < 1e-9 * 2.0


@pytest.mark.parametrize("contact", METHODS)
def test_friction_turns_a_forward_throw_into_forward_spin(contact):
    ring = Ring(position=(0.0, 0.3), velocity=(2.0, 0.0), angular_velocity=0.0)
    scene = Scene(rings=[ring], grounds=[Ground(friction=0.6)], contact=contact, dt=1e-3)
    traj = simulate(scene, 0.5)
    lift = next(t for t, _, kind in traj.events if kind == "liftoff")
    k = np.searchsorted(traj.t, lift) + 1
    spin = _spin(traj.x[k, 0], traj.v[k, 0])
    vx = traj.v[k, 0, :, 0].mean()
    assert spin < -2.0  # clockwise: rolling forward (+x)
    assert vx < 2.0  # friction took some of the forward speed


def test_a_ball_starting_below_a_ground_is_rejected():
    scene = Scene(rings=[Ring(position=(0.0, 0.05))], grounds=[Ground()])
    with pytest.raises(ValueError, match=r"below Scene.grounds\[0\]"):
        simulate(scene, 0.1)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"angle": 4.0}, "angle"),
        ({"angle": math.nan}, "angle"),
        ({"height": math.inf}, "height"),
        ({"friction": -0.1}, "friction"),
    ],
)
def test_ground_rejects_invalid_values(kwargs, field):
    with pytest.raises(ValueError, match=rf"Ground\.{field} = .* must be"):
        Ground(**kwargs)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"grounds": [1.0]}, "grounds"),
        ({"contact": "penalty"}, "contact"),
        ({"impulse_tol": 0.0}, "impulse_tol"),
        ({"friction_regularization": -1.0}, "friction_regularization"),
    ],
)
def test_scene_rejects_invalid_contact_settings(kwargs, field):
    with pytest.raises(ValueError, match=rf"Scene\.{field} = .* must be"):
        Scene(**kwargs)
