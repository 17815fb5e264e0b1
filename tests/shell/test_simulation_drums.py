"""simulate with drums, each against its closed form: a ball dropped inside a fixed drum stays inside
and comes to rest at its bottom, its centre ``R - r`` below the axis; a frictionless drum turning
under a ball steps bit for bit as a fixed one; a turning drum with friction drags a resting ball,
which slips at Coulomb's force until its contact point moves with the surface (a thin shell:
``I = 2/3 m r^2``, so its centre then moves at 2/5 of the surface's speed), never holding more
energy than it had plus the drum's credited work; a ball dropped onto a fixed frictionless cylinder
touches it when free fall says, never passes through it, and bounces off it with its angular
momentum about the axis changed only by gravity's torque."""

import numpy as np
import pytest

from ballenv.shell import Drum, Scene, Shell, equilibrium, simulate
from ballenv.shell.simulation import build
from ballenv.shell.skin.model import build_model
from ballenv.shell.step.implicit import total_energy

G = 9.81
R = 0.4  # m: the drum's radius
SHELL = Shell(subdivisions=1, position=(0.0, 0.0, -0.1))  # 42 vertices


def centre(mass, a):
    """Mass-weighted mean of ``a`` (..., V, 3) over the vertices."""
    return np.einsum("...vk,v->...k", a, mass) / mass.sum()


def axis_distance(x, axis=(0.0, 1.0, 0.0), origin=(0.0, 0.0, 0.0)):
    """Distance (m) of the points ``x`` (..., 3) from the line through ``origin`` along ``axis``."""
    r = x - np.array(origin)
    return np.linalg.norm(r - (r @ np.array(axis))[..., None] * np.array(axis), axis=-1)


def rigid_motion(mass, x, v):
    """The centre's velocity (3,) m/s and the angular velocity (3,) rad/s of the least-squares rigid
    motion of the vertex velocities ``v`` at ``x`` (V, 3)."""
    c, vc = centre(mass, x), centre(mass, v)
    r, u = x - c, v - vc
    inertia = np.einsum("v,vk,vl->kl", mass, r, r)
    inertia = np.trace(inertia) * np.eye(3) - inertia
    return vc, np.linalg.solve(inertia, np.einsum("v,vk->k", mass, np.cross(r, u)))


@pytest.fixture(scope="module")
def settled():
    """The ball dropped 0.17 m inside a fixed drum (mu 0.5) until it rests at the bottom (backward
    Euler's long fixed steps damp its bounces): the trajectory, vertex masses and rest radius (m)."""
    x = equilibrium(SHELL).x
    mass = build_model(SHELL).mass
    radius = float(np.linalg.norm(x - centre(mass, x), axis=1).mean())
    scene = Scene(
        shells=[SHELL],
        drums=[Drum(radius=R, friction=0.5)],
        integrator="backward_euler",
        adaptive=False,
        dt=0.01,
    )
    return simulate(scene, t_end=1.0), mass, radius


def test_a_ball_dropped_inside_a_fixed_drum_stays_inside_and_rests_at_the_bottom(settled):
    traj, mass, radius = settled
    assert axis_distance(traj.x).max() < R  # no vertex ever reaches the drum
    assert [kind for _, _, kind, _ in traj.events][:2] == ["touchdown", "liftoff"]
    c = centre(mass, traj.x[-1, 0])
    # at rest at the bottom: R - r below the axis, within the barrier's gap and the squash (~1 mm)
    assert c == pytest.approx([0.0, 0.0, -(R - radius)], abs=1.5e-3)
    assert np.abs(traj.v[-1, 0]).max() < 1e-3


def run_from_rest(settled, drum, t_end, output_dt=0.005):
    """``drum`` under the settled ball from rest, by generalized-alpha (rtol 1e-4)."""
    traj = settled[0]
    scene = Scene(shells=[SHELL], drums=[drum])
    return scene, simulate(
        scene, t_end=t_end, x0=traj.x[-1], v0=np.zeros_like(traj.x[-1]), output_dt=output_dt
    )


def test_a_frictionless_turning_drum_steps_bit_for_bit_as_a_fixed_one(settled):
    fixed = run_from_rest(settled, Drum(radius=R), 0.05)[1]
    turning = run_from_rest(settled, Drum(radius=R, angular_velocity=3.0), 0.05)[1]
    assert np.array_equal(fixed.x, turning.x) and np.array_equal(fixed.v, turning.v)
    assert np.all(turning.boundary_work == 0.0)


def test_a_turning_drum_drags_the_ball_until_its_contact_point_moves_with_the_surface(settled):
    mass = settled[1]
    mu, omega = 0.5, 0.25  # surface speed U = Omega R = 0.1 m/s
    speed = omega * R
    drum = Drum(radius=R, friction=mu, angular_velocity=omega)
    scene, traj = run_from_rest(settled, drum, 0.06, output_dt=0.001)
    tangent = np.array([-1.0, 0.0, 0.0])  # the surface's direction at the bottom: Omega y x (-R z)
    centre_speed, contact_speed = [], []
    for x, v in zip(traj.x[:, 0], traj.v[:, 0], strict=True):
        vc, spin = rigid_motion(mass, x, v)
        down = (R - axis_distance(centre(mass, x))) * np.array([0.0, 0.0, -1.0])
        centre_speed.append(vc @ tangent)
        contact_speed.append((vc + np.cross(spin, down)) @ tangent)
    centre_speed, contact_speed = np.array(centre_speed), np.array(contact_speed)
    # slipping: friction mu m g accelerates the centre at mu g and spins the ball at 3 mu g / (2 r),
    # so the contact point gains 5/2 mu g; it moves with the surface from t* = 2 U / (5 mu g), the
    # centre then at 2 U / 5 (a thin shell, I = 2/3 m r^2)
    t_stick = 2 * speed / (5 * mu * G)  # 8.2 ms
    slipping = (traj.t > 0.0) & (traj.t < 0.6 * t_stick)
    assert centre_speed[slipping] == pytest.approx(mu * G * traj.t[slipping], rel=0.1)
    # rolling: the ball rocks about the no-slip state on its 42 vertices (about +-20 % at some 50 Hz)
    # and starts climbing the wall, so the check is on the means over the 2 t* .. 60 ms
    rolling = traj.t > 2 * t_stick
    assert contact_speed[rolling].mean() == pytest.approx(speed, rel=0.03)
    assert centre_speed[rolling].mean() == pytest.approx(0.4 * speed, rel=0.1)
    # energy: never above its start plus the drum's credited work, which is positive
    st = build(scene)[1][0]
    energy = np.array([total_energy(st, x[0], v[0]) for x, v in zip(traj.x, traj.v, strict=True)])
    assert traj.boundary_work[-1, 0] > 0.0
    assert np.all(energy <= energy[0] + traj.boundary_work[:, 0] + 1e-9 * abs(energy[0]))


def test_a_ball_dropped_on_a_fixed_cylinder_touches_it_when_free_fall_says_and_bounces_off_it():
    radius = 0.15
    ball = Shell(subdivisions=1)
    x = equilibrium(ball).x
    mass = build_model(ball).mass
    x = x - centre(mass, x) + np.array([0.04, 0.0, radius + 0.16])  # 3 cm above it, 4 cm off its top
    scene = Scene(shells=[ball], drums=[Drum(radius=radius, inside=False)], rho_infinity=1.0)
    traj = simulate(scene, t_end=0.2, x0=x[None], v0=np.zeros((1, *x.shape)))
    assert (axis_distance(traj.x) - radius).min() > 0.0  # never through the cylinder
    # free fall until the lowest vertex is within dhat of it: the first touchdown
    lo, hi = 0.0, 0.15  # the gap falls monotonically over these 11 cm of fall
    for _ in range(60):
        t = 0.5 * (lo + hi)
        falling = x - np.array([0.0, 0.0, 0.5 * G * t * t])
        lo, hi = (t, hi) if (axis_distance(falling) - radius).min() > 1e-3 else (lo, t)
    touchdown, liftoff = (
        next(t for t, _, k, _ in traj.events if k == kind) for kind in ("touchdown", "liftoff")
    )
    # the event is placed linearly in the step in which the barrier engages (its end already held
    # off the cylinder, not falling freely): within a fraction of that step (<= Scene.dt = 2 ms)
    assert touchdown == pytest.approx(lo, abs=5e-4)
    # frictionless: the barrier pushes each vertex straight away from the axis, so the ball's angular
    # momentum about the axis, L = sum m (z v_x - x v_z), changes only by gravity's torque M g c_x
    c, v = centre(mass, traj.x[:, 0]), centre(mass, traj.v[:, 0])
    momentum = np.einsum(
        "v,tv->t", mass, traj.x[:, 0, :, 2] * traj.v[:, 0, :, 0] - traj.x[:, 0, :, 0] * traj.v[:, 0, :, 2]
    )
    torque = mass.sum() * G * c[:, 0]
    gained = np.concatenate([[0.0], np.cumsum(0.5 * (torque[1:] + torque[:-1]) * np.diff(traj.t))])
    after = np.flatnonzero(traj.t > liftoff)[0]
    # (to the integrator's accuracy through the bounce: 0.5 % at rtol 1e-4 without numerical damping)
    assert momentum[after] - momentum[0] == pytest.approx(gained[after], rel=1e-2)
    assert v[after, 0] > 0.0 and v[after, 2] > 0.0  # bounced up and away from the axis


def test_a_vertex_outside_an_inside_drum_or_inside_an_outside_one_is_an_error():
    with pytest.raises(ValueError, match=r"Scene.shells\[0\].position = \(0.0, 0.0, -0.1\) .* drums\[0\]"):
        simulate(Scene(shells=[SHELL], drums=[Drum(radius=0.2)]), t_end=0.01)
    with pytest.raises(ValueError, match=r"m inside drums\[1\]; every vertex must start outside it"):
        simulate(Scene(shells=[SHELL], drums=[Drum(radius=R), Drum(radius=0.05, inside=False)]), t_end=0.01)


@pytest.mark.slow  # compiles the joint step of shells in contact with drums (about 2 min, once)
def test_two_balls_colliding_along_a_frictionless_drum_keep_their_momentum_along_its_axis():
    """The drum pushes only across its axis and the balls' contact is frictionless: the momentum
    along the axis is the first ball's throughout, and the collision hands it to the second."""
    ball = Shell(subdivisions=1)
    x = equilibrium(ball).x
    mass = build_model(ball).mass
    radius = float(np.linalg.norm(x - centre(mass, x), axis=1).max())
    depth = -(R - radius - 2e-3)  # 2 mm above the bottom
    xs = np.stack([x - centre(mass, x) + np.array([0.0, y, depth]) for y in (-0.15, 0.15)])
    vs = np.zeros_like(xs)
    vs[0, :, 1] = 0.5  # m/s along the axis, toward the other ball
    scene = Scene(shells=[ball, ball], drums=[Drum(radius=R)])
    traj = simulate(scene, t_end=0.2, x0=xs, v0=vs, output_dt=0.01)
    assert axis_distance(traj.x).max() < R
    momentum = np.einsum("v,tsv->t", mass, traj.v[..., 1])
    assert momentum == pytest.approx(0.5 * mass.sum(), rel=1e-6)
    v = centre(mass, traj.v)[-1, :, 1]
    # equal masses with a restitution e in (0, 1]: v0' = (1 - e) v / 2 in [0, v/2), v1' = (1 + e) v / 2
    assert 0.0 <= v[0] < 0.25 < v[1] <= 0.5
    gap = np.linalg.norm(centre(mass, traj.x)[:, 0] - centre(mass, traj.x)[:, 1], axis=1)
    assert gap.min() < 2 * radius + 1e-3  # they touched
