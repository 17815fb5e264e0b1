"""Contact between rings through the barrier, solved jointly: the pairs' Hessian and the joint
Newton correction against finite differences, continuous detection of a thin-wall crossing, and the
scenes (head-on collision, five balls stacked in a narrow box)."""

from dataclasses import replace

import numpy as np
import pytest

from ballenv.physics import Ground, Ring, Scene, simulate
from ballenv.physics.base.ring import inflated_radius
from ballenv.physics.build import build_collision_workspace, build_model, build_ring_contact_workspace
from ballenv.physics.simulation import Simulation
from ballenv.physics.step.joint_newton import joint_correction, joint_predict, joint_residual, rings_met
from ballenv.physics.step.newton import COUPLED
from ballenv.physics.walls.impulses import rings_intrude
from ballenv.physics.walls.ring_barrier import (
    closest_ratio,
    contact_force,
    find_ring_pairs,
    impact_fraction,
    pair_hessians,
    pair_stiffness,
)
from ballenv.physics.walls.self_barrier import BETA_AT_STOP_GAP
from tests.physics.walls.test_impulses import box, mirrored_pair, no_intrusion, polygon
from tests.stability.invariants import audit


def touching_pair(n=16, gap=-0.002, speed=1.0, **scene):
    """Two equal rings whose facing edges are 2 mm apart (within the 4 mm contact distance; ``gap``
    is that of the circles through their nodes), closing at ``2 speed`` (m/s), as a Simulation."""
    rings, x0, v0, _ = mirrored_pair(n, speed, gap=gap)
    return Simulation(Scene(rings=rings, gravity=0.0, **scene), x0=x0, v0=v0)


def closest(scene, traj):
    """The smallest node-edge distance between rings over the records, in contact distances."""
    model = build_model(scene)
    rw = build_ring_contact_workspace(len(scene.rings), scene.rings[0].n_nodes)
    return min(closest_ratio(model, np.ascontiguousarray(x), rw) for x in traj.x)


# ---------------------------------------------------------------------------- the Jacobian
def test_pair_hessians_are_the_derivative_of_the_force():
    sim = touching_pair()
    model, rw = sim.model, build_ring_contact_workspace(2, 16)
    rng = np.random.default_rng(3)
    x = sim.state.x + 2e-4 * rng.standard_normal(sim.state.x.shape)
    count = find_ring_pairs(model, x, x, rw)
    pairs = rw.pairs[:count].copy()

    def force(y):
        f = np.zeros_like(y)
        contact_force(model, y, pairs, count, f, rw)
        return f.ravel()

    assert np.abs(force(x)).max() > 1.0  # pairs within the contact distance push
    pair_hessians(model, x, pairs, count, 1.0, rw)
    hess = np.zeros((x.size, x.size))
    n = x.shape[1]
    for c in range(count):
        if not rw.within[c]:
            continue
        a, i, b, j = pairs[c]
        dofs = [2 * (a * n + i), 2 * (b * n + j), 2 * (b * n + (j + 1) % n)]
        index = [k + d for k in dofs for d in range(2)]
        hess[np.ix_(index, index)] += rw.hessians[c]
    eps = 1e-8
    fd = np.zeros_like(hess)
    for k in range(x.size):
        dx = np.zeros(x.size)
        dx[k] = eps
        fd[:, k] = -(force(x + dx.reshape(x.shape)) - force(x - dx.reshape(x.shape))) / (2 * eps)
    assert np.abs(hess - fd).max() <= 1e-5 * np.abs(hess).max()
    assert np.abs(hess - hess.T).max() <= 1e-12 * np.abs(hess).max()


@pytest.mark.parametrize("integrator", ["generalized_alpha", "backward_euler"])
def test_joint_newton_correction_is_the_dense_solve_of_the_finite_difference_jacobian(integrator):
    # two pressurised, damped rings (low-rank columns in each ring's block) pressed together: the
    # joint correction (per-ring band solves plus the Woodbury coupling) against a dense solve
    sim = touching_pair(damping=30.0, damping_mode="rigid", integrator=integrator)
    model, solver, ws = sim.model, sim.solver, sim.ws
    state, trial, rc = sim.state, sim.trial, ws.ring_contact
    rc.mode[0] = COUPLED
    h = 2e-4
    trial.active[:] = state.active
    assert joint_predict(model, solver, state, state.v, h, ws, rc)
    rng = np.random.default_rng(0)
    rc.dx[:] += 3e-4 * rng.standard_normal(rc.dx.shape)
    dx = rc.dx.copy()

    def res(y):
        rc.dx[:] = y
        merit, _, finite = joint_residual(model, solver, state, state.v, trial, h, ws, rc)
        assert finite
        return rc.res.ravel().copy()

    r0 = res(dx)
    assert rc.force.any()  # the rings push each other at this iterate
    eps = 1e-8
    jac = np.zeros((r0.size, r0.size))
    for k in range(r0.size):
        d = np.zeros(r0.size)
        d[k] = eps
        jac[:, k] = (res(dx + d.reshape(dx.shape)) - res(dx - d.reshape(dx.shape))) / (2 * eps)
    expected = np.linalg.solve(jac, r0)
    res(dx)
    ok, _ = joint_correction(model, solver, state, state.v, trial, h, ws, rc)
    assert ok
    assert rc.first[2] > 0  # nodes coupled across rings
    assert np.abs(rc.step.ravel() - expected).max() <= 1e-5 * np.abs(expected).max()


# --------------------------------------------------------------------- continuous detection
def test_continuous_detection_catches_a_thin_wall_crossing_the_end_states_miss():
    # ring 1: a flat ring 2 mm thick; ring 0: a 2 mm ring that moves 10 mm straight down through it
    n = 16
    theta = 2 * np.pi * np.arange(n) / n
    flat = np.stack([0.05 * np.cos(theta), 0.001 * np.sin(theta)], axis=1)
    small = polygon((0.0, 0.005), 0.002, n)
    xa = np.stack([small, flat])
    xb = np.stack([small - (0.0, 0.01), flat])
    rings = [
        Ring(radius=0.002, n_nodes=n, thickness=2e-4, pressure=1e3),
        Ring(radius=0.05, n_nodes=n, thickness=2e-4, pressure=1e3),
    ]
    model = build_model(Scene(rings=rings, gravity=0.0))
    rw = build_ring_contact_workspace(2, n)
    cw = build_collision_workspace(2, n)
    for x in (xa, xb):  # both ends: clear of the contact distance, nothing inside the other ring
        assert closest_ratio(model, x, rw) > 5.0
        assert not rings_intrude(x, model.thickness, cw)
    count = find_ring_pairs(model, xa, xb, rw)
    first = impact_fraction(xa, xb, rw.pairs, count)
    assert first == pytest.approx(0.2, rel=1e-9)  # the bottom node meets the top wall 2 mm into 10 mm
    assert rings_met(model, xa, xb, rw)


# ------------------------------------------------------------------------------- the scenes
def test_only_barrier_scenes_with_colliding_rings_hold_the_joint_step():
    ring = Ring()
    assert Simulation(Scene(rings=[ring])).ws.ring_contact is None  # one ring (and the env)
    two = [ring, Ring(position=(1.0, 0.0))]
    assert Simulation(Scene(rings=two, self_intersection="reject")).ws.ring_contact is None
    assert Simulation(Scene(rings=two, ring_collision=False)).ws.ring_contact is None
    assert Simulation(Scene(rings=two)).ws.ring_contact is not None


@pytest.mark.parametrize("integrator", ["generalized_alpha", "backward_euler"])
def test_thirty_metres_per_second_head_on_stays_clear_of_the_other_wall(integrator):
    rings, x0, v0, _ = mirrored_pair(32, 15.0, gap=0.2)  # 30 m/s closing speed, 10 ms largest step
    scene = Scene(rings=rings, gravity=0.0, dt=1e-2, adaptive=True, integrator=integrator)
    traj = simulate(scene, 0.03, x0=x0, v0=v0)  # every accepted state recorded
    assert closest(scene, traj) > 0.5  # of the contact distance; measured 0.81 and 0.86
    assert traj.v[-1, 0, :, 0].mean() < -10.0  # bounced (measured -11.6 and -11.2 m/s)
    energy = traj.energy()["total"].sum(axis=1)
    assert energy.max() <= energy[0] + 1e-12 * abs(energy[0])
    # no step rejected but by the error control's own estimate (measured: 2 and 1)
    assert sum(n for reason, n in traj.stats.rejections.items() if reason != "error") == 0


@pytest.mark.parametrize("integrator", ["generalized_alpha", "backward_euler"])
def test_head_on_collision_through_the_barrier(integrator):
    rings, x0, v0, mirror = mirrored_pair(32, 3.0)
    scene = Scene(rings=rings, gravity=0.0, dt=1e-3, adaptive=True, integrator=integrator, newton_tol=1e-12)
    traj = simulate(scene, 0.03, x0=x0, v0=v0)
    momentum = traj.v.sum(axis=2)
    one_ball = np.abs(momentum[0, 0, 0])
    assert np.abs(momentum.sum(axis=1)).max() <= 1e-12 * one_ball  # measured 1e-15
    assert traj.v[-1, 0, :, 0].mean() < -1.5  # bounced back (measured -2.5 and -2.0 m/s from 3)
    image = traj.x[:, 0][:, mirror] * (-1.0, 1.0)
    assert np.abs(image - traj.x[:, 1]).max() <= 1e-9  # measured 5e-15 and 5e-13 m
    assert no_intrusion(traj.x, np.full(2, rings[0].thickness))
    assert closest(scene, traj) > 0.5  # measured 0.956 and 0.964 of the contact distance
    assert traj.stats.collision_gain == 0.0
    parts = traj.energy()
    # counted in the energy: at most 1.8e-3 J (generalized-alpha) and 9e-4 J (backward Euler) in the
    # records, of 0.25 J of kinetic energy
    assert parts["ring_contact"].sum(axis=1).max() > 5e-4
    energy = parts["total"].sum(axis=1)
    assert energy.max() <= energy[0] + 1e-12 * abs(energy[0])
    assert traj.stats.rejections["energy"] == 0


def five_balls(mode, impulse_tol=2e-3):
    """Five pressurised balls stacked in a box 1.3 mm wider than a ball on each side."""
    ring = Ring(radius=0.1, n_nodes=32, pressure=30e3)
    r = inflated_radius(ring)
    rings = [
        Ring(
            radius=0.1,
            n_nodes=32,
            pressure=30e3,
            position=(0.003 * (-1) ** k, r + 0.005 + (2 * r + 0.01) * k),
        )
        for k in range(5)
    ]
    return Scene(
        rings=rings, grounds=box(r + 0.006, 2.0, 0.3)[:3], damping=20.0, damping_mode="centre_of_mass",
        dt=1e-2, adaptive=True, impulse_tol=impulse_tol, self_intersection=mode,
    )  # fmt: skip


def test_five_balls_stacked_in_a_narrow_box_settle():
    scene = five_balls("barrier")
    traj = simulate(scene, 3.0)  # every step: the solver's states, not interpolated records
    kinetic = traj.energy()["kinetic"].sum(axis=1)
    assert kinetic.max() > 1e-2  # they fell and hit each other (measured 0.018 J)
    # no jiggle over the last 0.5 s: measured 1.7e-6 J, still decaying (1e-7 J at 4 s); the explicit
    # impulses ("reject") keep these balls jiggling at 8e-3 J
    assert kinetic[traj.t > 2.5].max() < 1e-5
    assert closest(scene, traj) > 0.9  # resting at the contact distance (measured 0.96)
    assert no_intrusion(traj.x, np.full(5, scene.rings[0].thickness))
    centres = traj.centre_of_mass()[-1]
    assert np.all(np.diff(centres[:, 1]) > 0.2)  # stacked in order
    assert traj.stats.collision_gain == 0.0
    energy = traj.energy()["total"].sum(axis=1)  # with the contact energy between the rings
    assert np.all(np.diff(energy) <= 1e-12 * np.abs(energy[1:]))  # damped: never gains


def test_the_pair_stiffness_spends_both_rings_start_energy():
    """``kappa = max(min(EA_a / l_a, EA_b / l_b), (K_a + K_b) / (dhat^2 beta(STOP_GAP^2)))``, ``dhat =
    h_a + h_b``: the softer edge at rest; thrown, both rings' kinetic energies are spent before a
    pair comes within ``STOP_GAP dhat``."""
    soft, stiff = Ring(youngs_modulus=1e6, pressure=None), Ring(position=(1.0, 0.0))
    model = build_model(Scene(rings=[soft, stiff]))
    assert pair_stiffness(model, 0, 1) == pytest.approx(model.ea[0] / model.rest_len[0], rel=1e-15)
    thrown = build_model(
        Scene(rings=[replace(soft, velocity=(20.0, 0.0)), replace(stiff, velocity=(-20.0, 0.0))])
    )
    energy = thrown.start_energy.sum()
    reach = soft.thickness + stiff.thickness
    assert pair_stiffness(thrown, 0, 1) == pytest.approx(energy / (reach**2 * BETA_AT_STOP_GAP), rel=1e-12)
    assert pair_stiffness(thrown, 1, 0) == pair_stiffness(thrown, 0, 1)


def test_rings_in_contact_whose_own_wall_kicks_itself_keep_their_energy_budgets():
    """Two balls thrown at 25 and 22 m/s into each other over a floor (soak scene 1388): in a joint
    step a self-contact impulse cost one ring 55-70 J at the step's start. The contact's energy
    transfer between the rings shared that loss out by contact work, so the ring was credited it
    twice, its energy test saw a gain of about 40 J at every step size, and the run stopped at
    dt_min ("the step gained energy"). Its own kicks are now left out of the transfer."""
    ring = Ring(radius=0.050581872056512864, n_nodes=32, youngs_modulus=197823.53868066674,
                thickness=0.006362159545723597, width=0.06725858587520636, density=1792.7105661788262,
                pressure=2574.9158579370846)  # fmt: skip
    rings = [
        replace(ring, position=(0.0, 0.20145970193640308), velocity=(20.792215154302326, -13.774950323446678),
                angular_velocity=17.832775309674915),
        replace(ring, position=(0.6043791058092093, 0.20145970193640308),
                velocity=(-6.9087208854917534, -20.614875113935458), angular_velocity=14.281468174389161),
    ]  # fmt: skip
    scene = Scene(rings=rings, grounds=[Ground(friction=1.0931865797432045)], contact="predictor_corrector",
                  gravity=4.6807947853972305, damping=0.0, rho_infinity=0.33103762854561614,
                  dt=0.000855452091877435, adaptive=True, impulse_tol=5e-3, gas_exponent=1.0)  # fmt: skip
    result = audit(scene, 0.04611550986791537)
    assert result.reached_end and result.problems() == [], result
