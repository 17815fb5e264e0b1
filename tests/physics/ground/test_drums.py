"""Drums (circular grounds turning about their centre): a ring at rest in a fixed drum, rolling
without slip in a turning one, the energy budget crediting the drum's work, the contact rows'
Jacobian against finite differences, and bad parameters (``Drum``, ``ground_motion.py``,
``contact.py``)."""

import math

import numpy as np
import pytest

from ballenv.physics import Drum, Ring, Scene, simulate
from ballenv.physics.base.layout import (
    GROUND_DRUM_INSIDE,
    GROUND_DRUM_OUTSIDE,
    GROUND_KIND,
    SURFACE_SPIN,
    SURFACE_TURN,
)
from ballenv.physics.base.linalg import BAND_COLUMNS, BAND_HALF_WIDTH, MAX_LOW_RANK, zigzag_positions
from ballenv.physics.base.ring import inflated_radius, total_mass
from ballenv.physics.ground.contact import constrain_jacobian, constrain_residual
from ballenv.physics.ground.motion import ground_array, ground_surfaces, surface_array

N_NODES = 32
BALL = Ring(radius=0.05, n_nodes=N_NODES)
RADIUS = inflated_radius(BALL)  # m: the inflated circle's radius (54 mm)
MASS = total_mass(BALL)  # kg
DRUM_RADIUS = 0.25  # m
SPIN = 3.0  # rad/s: the drum's surface speed Omega R_d = 0.75 m/s, Froude number Omega^2 R_d / g = 0.23
G = 9.81
INTEGRATORS = ("generalized_alpha", "backward_euler")


def _in_drum(drum, t_end, angular_velocity=0.0, damping=20.0, **scene_kw):
    """A ring set at the bottom of ``drum`` (centre at the origin; its lowest node 0.1 mm above the
    circle), spinning at ``angular_velocity`` (rad/s); every step recorded."""
    ring = Ring(
        radius=0.05,
        n_nodes=N_NODES,
        position=(0.0, -DRUM_RADIUS + RADIUS + 1e-4),
        angular_velocity=angular_velocity,
    )
    kw = dict(adaptive=True, dt=1e-3, damping=damping)
    kw.update(scene_kw)
    return simulate(Scene(rings=[ring], drums=[drum], **kw), t_end)


def _contact_frames(traj, spin):
    """Per record and node: the slip ``t . (v - w)`` (m/s) relative to the drum's surface turning at
    ``spin`` (T,) rad/s, and the contact force's normal and tangential parts (N), on a drum centred
    at the origin with the rings inside (``n = -x / |x|``)."""
    x, v, f = traj.x[:, 0], traj.v[:, 0], traj.contact_force[:, 0]
    n = -x / np.linalg.norm(x, axis=-1)[..., None]
    t = np.stack([-n[..., 1], n[..., 0]], axis=-1)
    w = spin[:, None, None] * np.stack([-x[..., 1], x[..., 0]], axis=-1)
    return np.sum((v - w) * t, axis=-1), np.sum(f * n, axis=-1), np.sum(f * t, axis=-1)


def _rigid_motion(traj):
    """Centre of mass (T, 2) m, its velocity (T, 2) m/s and the ring's spin about it (T,) rad/s
    (angular momentum over moment of inertia, equal node masses)."""
    x, v = traj.x[:, 0], traj.v[:, 0]
    c, vc = x.mean(axis=1), v.mean(axis=1)
    xr, vr = x - c[:, None], v - vc[:, None]
    spin = np.sum(xr[..., 0] * vr[..., 1] - xr[..., 1] * vr[..., 0], axis=-1) / np.sum(xr**2, axis=(-1, -2))
    return c, vc, spin


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"radius": 0.0}, "radius"),
        ({"radius": -1.0}, "radius"),
        ({"radius": float("nan")}, "radius"),
        ({"centre": (0.0,)}, "centre"),
        ({"centre": (float("inf"), 0.0)}, "centre"),
        ({"inside": 1}, "inside"),
        ({"friction": -0.1}, "friction"),
        ({"friction": 11.0}, "friction"),
        ({"angular_velocity": 2e4}, "angular_velocity"),
        ({"angular_velocity": float("nan")}, "angular_velocity"),
        ({"spin_up": -1.0}, "spin_up"),
    ],
)
def test_drum_rejects_invalid_values_naming_the_field_value_and_range(kwargs, field):
    with pytest.raises(ValueError, match=rf"Drum\.{field} = .* is out of range: must be"):
        Drum(**kwargs)


def test_drum_errors_name_the_range_and_the_scene_checks_its_drums():
    with pytest.raises(ValueError, match=r"Drum\.radius = 0\.0 .* in \(0, 1e\+06\] m"):
        Drum(radius=0.0)
    with pytest.raises(ValueError, match=r"Drum\.angular_velocity = 20000\.0 .* \[-10000, 10000\] rad/s"):
        Drum(angular_velocity=2e4)
    with pytest.raises(ValueError, match=r"Scene\.drums = .* sequence of Drum"):
        Scene(drums=["drum"])
    outside = Ring(radius=0.05, n_nodes=N_NODES, position=(0.0, -0.24))
    with pytest.raises(ValueError, match=r"outside Scene\.drums\[0\]: every node must start inside the drum"):
        simulate(Scene(rings=[outside], drums=[Drum(radius=DRUM_RADIUS)]), 1e-3)
    with pytest.raises(ValueError, match=r"Scene\.drums\[0\]: every node must start outside the drum"):
        simulate(Scene(rings=[Ring(position=(0.0, 0.0))], drums=[Drum(radius=0.5, inside=False)]), 1e-3)


def test_drum_rows_spin_up_linearly_and_turn_by_the_integral_of_the_spin():
    """``Omega(t) = Omega_0 min(1, t / T)`` and ``theta(t) = int_0^t Omega``, checked against the
    trapezoidal rule (exact for a piecewise linear Omega with T on the grid)."""
    drums = (Drum(radius=0.3, angular_velocity=-2.0, spin_up=0.5), Drum(radius=0.1, inside=False))
    rows = ground_array((), drums)
    assert rows[0, GROUND_KIND] == GROUND_DRUM_INSIDE and rows[1, GROUND_KIND] == GROUND_DRUM_OUTSIDE
    out = surface_array(2)
    t = np.linspace(0.0, 1.0, 101)
    spin, turn = [], []
    for tk in t:
        ground_surfaces(rows, tk, out)
        spin.append(out[0, SURFACE_SPIN])
        turn.append(out[0, SURFACE_TURN])
        assert out[1, SURFACE_SPIN] == 0.0 and out[1, SURFACE_TURN] == 0.0
    np.testing.assert_allclose(spin, -2.0 * np.minimum(1.0, t / 0.5), rtol=0, atol=1e-15)
    trapezoid = np.concatenate([[0.0], np.cumsum(0.5 * (np.array(spin[1:]) + spin[:-1]) * np.diff(t))])
    np.testing.assert_allclose(turn, trapezoid, rtol=0, atol=1e-14)


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_a_ring_in_a_fixed_drum_rests_at_the_bottom_carried_by_its_weight(integrator):
    """Released 0.1 mm above the bottom of a fixed drum with friction, the ring settles there: after
    1 s its centre is on the vertical through the drum's centre (to 1 um), every node at rest (to
    1 mm/s; measured 5e-5 generalized-alpha, 1e-12 backward Euler) and the drum carries its weight
    (to 1e-3). (This stiff ring, more curved than the drum, rests on its lowest node; damping
    100 /s settles its vertical vibration on that node within the second.)"""
    traj = _in_drum(Drum(radius=DRUM_RADIUS, friction=0.8), 1.0, integrator=integrator, damping=100.0)
    c, vc, spin = _rigid_motion(traj)
    assert abs(c[-1, 0]) < 1e-6 and c[-1, 1] < -DRUM_RADIUS + RADIUS
    assert np.abs(traj.v[-1, 0]).max() < 1e-3
    np.testing.assert_allclose(
        traj.contact_force[-1, 0].sum(axis=0), [0.0, MASS * G], rtol=0, atol=1e-3 * MASS * G
    )


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_a_ring_balances_on_top_of_a_fixed_drum_it_is_outside_of(integrator):
    """Set 0.1 mm above the top of a fixed drum of radius 0.2 m (``inside=False``), the ring lands
    on it and stays balanced there (by symmetry: the top is an unstable rest): after 0.5 s its
    centre is on the vertical to 1 um, its nodes at rest to 1 mm/s, and the drum's reaction over
    the last 0.1 s carries its weight to 1 % in the mean (measured 0.24 % generalized-alpha, whose
    single contact node still vibrates by 9 %; 1e-9 backward Euler)."""
    ring = Ring(radius=0.05, n_nodes=N_NODES, position=(0.0, 0.2 + RADIUS + 1e-4))
    drum = Drum(radius=0.2, inside=False, friction=0.5)
    scene = Scene(rings=[ring], drums=[drum], adaptive=True, dt=1e-3, impulse_tol=5e-3, damping=100.0,
                  integrator=integrator)  # fmt: skip
    traj = simulate(scene, 0.5)
    c, _, _ = _rigid_motion(traj)
    assert abs(c[-1, 0]) < 1e-6 and c[-1, 1] > 0.2
    assert np.abs(traj.v[-1, 0]).max() < 1e-3
    late = traj.t > 0.4
    h = np.gradient(traj.t)[late]
    lift = np.sum(traj.contact_force[late, 0, :, 1].sum(axis=1) * h) / np.sum(h)
    assert lift == pytest.approx(MASS * G, rel=0.01)


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_a_ring_rolls_without_slip_inside_a_drum_turning_at_constant_speed(integrator):
    """A ring started at the rolling speed ``omega = Omega R_d / r`` in a drum turning at
    Omega = 3 rad/s (mu = 0.8) rolls without slip: rigid-body kinematics of a ring of radius
    ``r_e = R_d - |c|`` (its centre ``c`` at distance ``|c|`` from the drum's) in contact at the
    drum's surface requires ``|c| dphi/dt + r_e omega = Omega R_d`` (the contact point moves with the
    surface; ``phi`` the centre's polar angle). Over 0.2 ... 1 s the time mean of the left side is
    ``Omega R_d`` = 0.75 m/s to 1 % (measured 0.16 % generalized-alpha, 0.27 % backward Euler; the
    ring rocks slightly about the bottom and its spin estimate L / I carries its vibrations, so
    single records scatter by up to 6 %), its mean spin is ``Omega R_d / r_e`` to 2 % (measured
    0.1 %, 0.5 %), and the slip of its contact nodes, weighted by their normal force, is under 2 % of
    the surface speed (measured 0.8 %, 0.07 %: the regularised friction's creep)."""
    traj = _in_drum(
        Drum(radius=DRUM_RADIUS, friction=0.8, angular_velocity=SPIN),
        1.0,
        angular_velocity=SPIN * DRUM_RADIUS / RADIUS,
        integrator=integrator,
    )
    speed = SPIN * DRUM_RADIUS
    c, vc, spin = _rigid_motion(traj)
    dist = np.linalg.norm(c, axis=1)
    polar_rate = (c[:, 0] * vc[:, 1] - c[:, 1] * vc[:, 0]) / dist**2
    later = traj.t > 0.2
    h = np.gradient(traj.t)[later]
    rolling = dist * polar_rate + (DRUM_RADIUS - dist) * spin
    assert np.sum(rolling[later] * h) / np.sum(h) == pytest.approx(speed, rel=0.01)
    mean_spin = np.sum(spin[later] * h) / np.sum(h)
    assert mean_spin == pytest.approx(speed / np.mean(DRUM_RADIUS - dist[later]), rel=0.02)
    slip, normal, _ = _contact_frames(traj, np.full(len(traj.t), SPIN))
    assert np.sum(np.abs(normal * slip)) / np.sum(np.abs(normal)) < 0.02 * speed
    assert traj.stats.rejections["energy"] == 0


def test_a_frictionless_drum_does_not_turn_the_ring():
    """Without friction the turning drum exerts only normal forces: the ring stays at the bottom
    without spinning (the spin left is its vibrations' share of L / I, under 1e-3 of the rolling
    spin Omega R_d / r), and the drum does no work."""
    traj = _in_drum(Drum(radius=DRUM_RADIUS, angular_velocity=SPIN), 0.5)
    c, _, spin = _rigid_motion(traj)
    assert np.abs(spin).max() < 1e-3 * SPIN * DRUM_RADIUS / RADIUS
    assert np.abs(c[:, 0]).max() < 1e-6
    assert traj.stats.boundary_work == 0.0


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_the_energy_budget_credits_the_work_of_a_turning_drum(integrator):
    """A drum spinning up to 3 rad/s over 0.5 s drags a ring at rest at its bottom into rolling
    (no damping). The credited boundary work equals the friction forces' work on the drum's surface
    recomputed from the recorded contact forces, ``sum_steps sum_i F_i s R_d (theta(t1) - theta(t0))``,
    to 1e-9; the budget never rejects a step nor removes energy; and the balance
    ``W = Delta E + D_friction + D_rest`` closes with a non-negative rest ``D_rest`` (the normal
    momentum of nodes arriving at the drum in rolling, and the integrator's dissipation) under 12 %
    of ``W`` for generalized-alpha (measured 9.5 %) and 35 % for backward Euler (measured 29 %,
    its numerical damping), ``D_friction`` the work of the friction forces on the recorded slips."""
    spin_up = 0.5
    traj = _in_drum(
        Drum(radius=DRUM_RADIUS, friction=0.8, angular_velocity=SPIN, spin_up=spin_up),
        1.0,
        damping=0.0,
        integrator=integrator,
    )
    t = traj.t
    stats = traj.stats
    spin = SPIN * np.minimum(1.0, t / spin_up)
    turn = np.where(t < spin_up, 0.5 * SPIN * t**2 / spin_up, SPIN * (t - 0.5 * spin_up))
    slip, _, friction = _contact_frames(traj, spin)
    recorded = np.sum(np.sum(friction[1:], axis=1) * -DRUM_RADIUS * np.diff(turn))  # s = -1: inside
    assert stats.boundary_work > 0.0
    assert stats.boundary_work == pytest.approx(recorded, rel=1e-9)
    assert stats.rejections["energy"] == 0 and stats.energy_removed == 0.0
    energy = traj.energy()["total"][:, 0]
    dissipated = -np.sum(np.diff(t) * np.sum(friction[1:] * slip[1:], axis=1))
    rest = stats.boundary_work - (energy[-1] - energy[0]) - dissipated
    assert dissipated > 0.0
    assert 0.0 <= rest < (0.12 if integrator == "generalized_alpha" else 0.35) * stats.boundary_work


def test_a_drum_scene_survives_a_save_and_load_round_trip(tmp_path):
    drum = Drum(radius=0.3, centre=(0.1, -0.2), inside=False, friction=0.4, angular_velocity=2.0, spin_up=0.5)
    scene = Scene(rings=[Ring(n_nodes=16, position=(0.1, 0.3))], drums=[drum])
    traj = simulate(scene, 0.01)
    loaded = type(traj).load(traj.save(tmp_path / "drum.npz"))
    assert loaded.scene == scene and loaded.scene.drums == (drum,)


def _drum_rows(side, spin, friction):
    drum = Drum(
        radius=0.3, centre=(0.1, -0.2), inside=side == "inside", friction=friction, angular_velocity=spin
    )
    rows = ground_array((), (drum,))
    out = surface_array(1)
    ground_surfaces(rows, 0.0, out)
    return out


@pytest.mark.parametrize("side", ["inside", "outside"])
@pytest.mark.parametrize(("spin", "friction"), [(0.0, 0.0), (0.0, 0.6), (4.0, 0.6), (-7.0, 2.0)])
def test_drum_contact_rows_jacobian_matches_finite_differences(side, spin, friction):
    """The constrained rows of a node on a drum (:func:`contact.constrain_residual`) as functions of
    its own position, with an unconstrained residual ``r = K x + b`` and velocity ``v = c_v (x - x0)
    + v0``, against the 2x2 block :func:`contact.constrain_jacobian` writes into the band (central
    differences, step 1e-8 m: to 1e-6 of the block's size). It holds the curvature of the circle
    (the normal turning with the node) and the surface velocity's change with the point."""
    rng = np.random.default_rng(7)
    surface = _drum_rows(side, spin, friction)
    n, i = 8, 3
    node_mass, c_mass, c_v, eps = 2e-3, 4e6, 2e3, 1e-2
    angle = 0.7
    r0 = 0.3 + (-1e-5 if side == "inside" else 1e-5)  # near the circle, on either side
    x_node = np.array([0.1 + r0 * math.cos(angle), -0.2 + r0 * math.sin(angle)])
    stiffness = rng.normal(size=(2, 2)) * 50.0
    offset = rng.normal(size=2) * 0.5
    x0 = x_node - np.array([5e-6, -8e-6])  # slips of the order of eps: s(v_t) far from saturated
    v0 = rng.normal(size=2) * 0.01
    active = np.full(n, -1, dtype=np.int64)
    active[i] = 0

    def rows(xi):
        x1 = np.zeros((n, 2))
        x1[i] = xi
        ve = np.zeros((n, 2))
        ve[i] = c_v * (xi - x0) + v0
        res = np.zeros(2 * n)
        res[2 * i : 2 * i + 2] = stiffness @ xi + offset
        scratch = [np.zeros(n) for _ in range(3)]
        constrain_residual(surface, active, x1, ve, res, node_mass, c_mass, eps, *scratch)
        return res[2 * i : 2 * i + 2].copy(), x1, ve, scratch

    _, x1, ve, (reaction, _, tangential) = rows(x_node)
    band = np.zeros((2 * n, BAND_COLUMNS))
    pos = zigzag_positions(n)
    p = 2 * pos[i]
    w = BAND_HALF_WIDTH
    for a in range(2):
        for b in range(2):
            band[p + a, w + b - a] = stiffness[a, b]
    u = np.zeros((2 * n, MAX_LOW_RANK))
    constrain_jacobian(
        surface, active, x1, ve, reaction, tangential, band, pos, u, 0, node_mass, c_mass, c_v, eps
    )
    jacobian = np.array([[band[p + a, w + b - a] for b in range(2)] for a in range(2)])
    step = 1e-8
    numeric = np.zeros((2, 2))
    for b in range(2):
        e = np.zeros(2)
        e[b] = step
        numeric[:, b] = (rows(x_node + e)[0] - rows(x_node - e)[0]) / (2 * step)
    np.testing.assert_allclose(jacobian, numeric, rtol=0, atol=1e-6 * np.abs(numeric).max())
