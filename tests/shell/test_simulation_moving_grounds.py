"""simulate on moving grounds, each against its closed form: a ball carried by a rising plate rises
with it; a ball dropped on a conveyor belt slips at mu g until it rolls with the belt (the rolling
speed from its angular momentum about the contact point); a ball on a vibrating table stays on it
while the table's peak acceleration is below g and bounces off (at the phase where the table's
deceleration first exceeds g) well above it, never holding more energy than it had plus the
table's work; fixed grounds step as before (and so does a frictionless belt, which moves only
along its plane)."""

import math

import numpy as np
import pytest

from ballenv.shell import Ground, Scene, Shell, equilibrium, simulate
from ballenv.shell.simulation import build
from ballenv.shell.skin.model import build_model
from ballenv.shell.step.implicit import total_energy

G = 9.81
GAP = 0.87e-3  # m: the barrier's static gap under the ball's weight (kappa = E h, dhat = 1 mm)


def centre(mass, a):
    """Mass-weighted mean of ``a`` (..., V, 3) over the vertices."""
    return np.einsum("...vk,v->...k", a, mass) / mass.sum()


@pytest.fixture(scope="module")
def resting():
    """The default ball (162 vertices) settled on a fixed floor: its positions (V, 3) m and vertex
    masses (V,) kg. Backward Euler's long fixed steps damp its bounce on the barrier away."""
    shell = Shell()
    x = equilibrium(shell).x
    mass = build_model(shell).mass
    lift = float((centre(mass, x) - x)[:, 2].max()) + GAP
    ball = Shell(position=(0, 0, lift))
    scene = Scene(shells=[ball], grounds=[Ground()], integrator="backward_euler", adaptive=False, dt=0.01)
    traj = simulate(scene, t_end=0.15)
    return traj.x[-1, 0], mass


def test_a_ball_on_a_rising_plate_rises_with_it_and_no_vertex_passes_it(resting):
    x0, mass = resting
    u = 0.5  # m/s
    scene = Scene(grounds=[Ground(velocity=(0, 0, u))], rtol=1e-3)
    traj = simulate(scene, t_end=0.2, x0=x0[None], v0=np.tile([0.0, 0.0, u], (1, len(x0), 1)))
    z = centre(mass, traj.x[:, 0])[:, 2]
    late = traj.t >= 0.05
    speed = np.polyfit(traj.t[late], z[late], 1)[0]
    assert speed == pytest.approx(u, rel=0.01)
    gaps = traj.x[:, 0, :, 2].min(axis=1) - u * traj.t  # the lowest vertex above the plate (m)
    assert gaps.min() > 0.25 * GAP
    assert not [e for e in traj.events if e[2] == "liftoff"]
    # lifting the weight at u: the energy grows by M g u t, no more than the plate's credited work
    st = build(scene)[1][0]
    energy = []
    for k in (0, -1):
        st.heights[:] = u * traj.t[k]
        energy.append(total_energy(st, traj.x[k, 0], traj.v[k, 0]))
    lift = mass.sum() * G * u * traj.t[-1]
    assert energy[1] - energy[0] == pytest.approx(lift, rel=0.02)
    assert traj.boundary_work[-1, 0] >= energy[1] - energy[0]


def test_a_ball_on_a_conveyor_belt_slips_at_mu_g_then_rolls_with_the_belt(resting):
    x0, mass = resting
    u, mu = 1.0, 0.5
    scene = Scene(grounds=[Ground(friction=mu, velocity=(u, 0, 0))], rtol=1e-3)
    traj = simulate(scene, t_end=0.3, x0=x0[None], output_dt=0.005)
    c, vc = centre(mass, traj.x[:, 0]), centre(mass, traj.v[:, 0])
    r = x0 - centre(mass, x0)
    inertia = float(np.sum(mass * (r[:, 0] ** 2 + r[:, 2] ** 2)))  # about y through the centre
    height = float(c[0, 2])  # of the centre above the belt: the rolling radius
    # the friction F at the contact point: M dv = F dt, I dw = -height F dt; slip ends when
    # v - w height = u: v = u I / (I + M height^2) (2 u / 5 for a thin shell, I = 2 M R^2 / 3)
    rolling = u * inertia / (inertia + mass.sum() * height**2)
    slip_end = rolling / (mu * G)
    early = traj.t <= 0.3 * slip_end  # before the mesh's lowest vertex rolls off
    assert np.allclose(vc[early, 0], mu * G * traj.t[early], atol=0.01 * rolling)
    about = np.cross(traj.x[:, 0] - c[:, None], traj.v[:, 0] - vc[:, None])[..., 1]  # (T, V)
    spin = about @ mass / inertia  # rad/s about y
    contact_point = vc[:, 0] - spin * c[:, 2]
    rolls = int(np.argmax(contact_point >= 0.99 * u))  # the first record without slip
    assert rolls > 0 and traj.t[rolls] == pytest.approx(slip_end, abs=0.01)
    assert vc[rolls, 0] == pytest.approx(rolling, rel=0.02)
    # then it rolls with the belt, rocking from vertex to vertex of its 162: on average
    late = traj.t >= 1.5 * slip_end
    assert np.mean(contact_point[late]) == pytest.approx(u, rel=0.02)
    assert np.mean(vc[late, 0]) == pytest.approx(rolling, rel=0.06)


def energy_excess(traj, amplitude, omega):
    """The largest ``E(t) - E(0) - W(t)`` (J) over the records, ``E`` the shell's total energy
    against the table at its height ``A sin(omega t)`` (m) and ``W`` the table's work."""
    steps = build(traj.scene)[1]
    st = steps[0]
    energies = []
    for t, x, v in zip(traj.t, traj.x[:, 0], traj.v[:, 0], strict=True):
        st.heights[:] = amplitude * math.sin(omega * t)
        energies.append(total_energy(st, x, v))
    return float(np.max(np.array(energies) - energies[0] - traj.boundary_work[:, 0]))


@pytest.mark.parametrize("gamma", [0.5, 3.0])
def test_a_ball_on_a_vibrating_table_leaves_it_only_when_the_table_outpulls_gravity(resting, gamma):
    x0, mass = resting
    frequency = 5.0  # Hz
    omega = 2 * math.pi * frequency
    amplitude = gamma * G / omega**2  # peak acceleration gamma g
    table = Ground(amplitude=amplitude, frequency=frequency)
    scene = Scene(grounds=[table], rtol=1e-3)
    v0 = np.tile([0.0, 0.0, amplitude * omega], (1, len(x0), 1))  # moving with the table at t = 0
    traj = simulate(scene, t_end=0.25, x0=x0[None], v0=v0)
    liftoffs = [t for t, _, kind, _ in traj.events if kind == "liftoff"]
    if gamma < 1.0:
        assert not liftoffs
    else:
        # a rigid ball leaves when the table decelerates by g, A omega^2 sin(omega t) = g; this one
        # is off the barrier's reach within an eighth of a period after
        leaves = math.asin(1.0 / gamma) / omega
        assert leaves < liftoffs[0] < leaves + 0.125 / frequency
    assert energy_excess(traj, amplitude, omega) <= 1e-9
    assert traj.boundary_work[-1, 0] > 0.0


def test_a_frictionless_belt_steps_bit_for_bit_as_a_fixed_floor(resting):
    x0, _ = resting
    runs = [
        simulate(Scene(grounds=[floor], rtol=1e-3), t_end=0.05, x0=x0[None], v0=np.full((1, len(x0), 3), 0.1))
        for floor in (Ground(), Ground(velocity=(1.0, 0.0, 0.0)))
    ]
    assert np.array_equal(runs[0].t, runs[1].t) and np.array_equal(runs[0].x, runs[1].x)
    assert np.array_equal(runs[0].contact_force, runs[1].contact_force)
    assert np.all(runs[1].boundary_work == 0.0)


def test_fixed_grounds_do_no_work_and_a_start_through_a_moving_ground_names_itself():
    scene = Scene(shells=[Shell(position=(0, 0, 0.2))], grounds=[Ground()], rtol=1e-2)
    traj = simulate(scene, t_end=0.01)
    assert np.all(traj.boundary_work == 0.0)
    plate = Ground(height=0.1, velocity=(0, 0, -1.0), amplitude=0.01, frequency=3.0)
    with pytest.raises(ValueError, match="through grounds\\[0\\]"):
        simulate(Scene(shells=[Shell(position=(0, 0, 0.2))], grounds=[plate]), t_end=0.01)
