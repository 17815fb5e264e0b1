"""The self-contact barrier: its distance derivatives and Jacobian against finite differences,
continuous collision detection, the broad phase, and rings whose far wall parts meet."""

from dataclasses import replace

import numpy as np
import pytest

from ballenv.physics import Ground, Ring, Scene, Simulation, simulate
from ballenv.physics.base.layout import ENERGY_TOTAL
from ballenv.physics.base.linalg import band_to_dense
from ballenv.physics.base.ring import inflated_radius, total_mass
from ballenv.physics.build import build_model, build_workspace, initial_state
from ballenv.physics.walls.impulses import self_intersects
from ballenv.physics.walls.self_barrier import (
    STOP_GAP,
    barrier_energy,
    barrier_force,
    barrier_jacobian,
    beta,
    beta_curvature,
    beta_slope,
    excluded,
    find_pairs,
    impact_fraction,
    near_pairs,
    point_edge_derivatives,
    point_edge_distance2,
    point_edge_impact,
    stiffness,
)
from tests.stability.invariants import audit

# p, a, b with the foot of p on the segment, beyond a, and beyond b
CONFIGURATIONS = {
    "line": (0.3, 0.2, -0.1, 0.05, 1.0, -0.1),
    "beyond a": (-0.4, 0.3, 0.0, 0.0, 1.0, 0.1),
    "beyond b": (1.5, -0.2, 0.0, 0.0, 1.0, 0.1),
}


def _derivatives(z):
    g, hess, scratch = np.zeros(6), np.zeros((6, 6)), np.zeros((6, 6))
    s = point_edge_derivatives(*z, g, hess, scratch)
    return s, g, hess


@pytest.mark.parametrize("where", list(CONFIGURATIONS))
def test_squared_distance_gradient_and_hessian_match_finite_differences(where):
    z = np.array(CONFIGURATIONS[where])
    s, g, hess = _derivatives(z)
    assert s == pytest.approx(point_edge_distance2(*z), rel=1e-14)
    eps = 1e-6
    g_fd = np.zeros(6)
    h_fd = np.zeros((6, 6))
    for k in range(6):
        dz = np.zeros(6)
        dz[k] = eps
        g_fd[k] = (point_edge_distance2(*(z + dz)) - point_edge_distance2(*(z - dz))) / (2 * eps)
        h_fd[:, k] = (_derivatives(z + dz)[1] - _derivatives(z - dz)[1]) / (2 * eps)
    np.testing.assert_allclose(g, g_fd, rtol=1e-8, atol=1e-9)
    np.testing.assert_allclose(hess, h_fd, rtol=1e-6, atol=1e-7)


def test_barrier_function_derivatives_and_support():
    y = np.linspace(0.05, 0.95, 19)
    eps = 1e-6
    slope_fd = np.array([(beta(t + eps) - beta(t - eps)) / (2 * eps) for t in y])
    curv_fd = np.array([(beta_slope(t + eps) - beta_slope(t - eps)) / (2 * eps) for t in y])
    np.testing.assert_allclose([beta_slope(t) for t in y], slope_fd, rtol=1e-7)
    np.testing.assert_allclose([beta_curvature(t) for t in y], curv_fd, rtol=1e-6)
    assert beta(1.0) == beta_slope(1.0) == beta_curvature(1.0) == 0.0  # C^2 at y = 1 (dhat)
    assert beta(1.0 - 1e-4) < 1e-11 and beta(0.0) == np.inf  # infinite at contact


def _folded_ring(n=24, gap=0.6e-3):
    """A ring squashed into a stadium: two straight walls ``gap`` (m) apart joined by half circles."""
    half = n // 2
    top = np.linspace(0.04, -0.04, half // 2)
    x = []
    arc = np.linspace(np.pi / 2, 3 * np.pi / 2, half // 2 + 2)[1:-1]
    x += [(t, gap / 2) for t in top]
    x += [(-0.04 + gap / 2 * np.cos(a), gap / 2 * np.sin(a)) for a in arc]
    x += [(t, -gap / 2) for t in -top]
    x += [(0.04 - gap / 2 * np.cos(a), -gap / 2 * np.sin(a)) for a in arc]
    return np.array(x[:n])


def _model_and_pairs(x, thickness=1e-3):
    n = x.shape[0]
    scene = Scene(rings=[Ring(n_nodes=n, pressure=None, thickness=thickness)], gravity=0.0)
    model = build_model(scene)
    ws = build_workspace(n)
    bw = ws.barrier
    count = find_pairs(x, x, model.rest_len[0], thickness, bw)
    return model, ws, count


def test_contact_jacobian_matches_finite_differences_of_the_force():
    rng = np.random.default_rng(3)
    x = _folded_ring() + rng.normal(scale=5e-5, size=(24, 2))
    model, ws, count = _model_and_pairs(x)
    bw = ws.barrier
    kappa, dhat = 1e3, 1e-3
    n = x.shape[0]

    def force(y):
        f = np.zeros((n, 2))
        barrier_force(y, bw.pairs, count, kappa, dhat, f, bw)
        return f.ravel()

    assert count > 0 and np.abs(force(x)).max() > 0.0  # the walls touch
    ws.band[:] = 0.0
    rank = barrier_jacobian(x, bw.pairs, count, kappa, dhat, 1.0, ws.band, ws.pos, bw.u, bw.w, 0, bw)
    assert 0 < rank <= 2 * n  # far wall parts coupled through low-rank columns
    dense = band_to_dense(ws.band, ws.pos) + bw.u[:, :rank] @ bw.w[:, :rank].T
    eps = 1e-9
    fd = np.zeros((2 * n, 2 * n))
    for k in range(2 * n):
        dx = np.zeros(2 * n)
        dx[k] = eps
        fd[:, k] = -(force(x + dx.reshape(n, 2)) - force(x - dx.reshape(n, 2))) / (2 * eps)
    scale = np.abs(fd).max()
    np.testing.assert_allclose(dense, fd, atol=1e-6 * scale)
    # and the force is minus the energy's gradient
    e_fd = np.zeros(2 * n)
    for k in range(2 * n):
        dx = np.zeros(2 * n)
        dx[k] = eps
        plus = barrier_energy(x + dx.reshape(n, 2), bw.pairs, count, kappa, dhat)
        minus = barrier_energy(x - dx.reshape(n, 2), bw.pairs, count, kappa, dhat)
        e_fd[k] = -(plus - minus) / (2 * eps)
    np.testing.assert_allclose(force(x), e_fd, atol=1e-6 * np.abs(e_fd).max())


def test_ccd_catches_a_fast_crossing_that_a_discrete_test_misses():
    # a node moving 1 m/s through a still edge in a 0.1 s step: 5 cm either side, so neither end
    # state has it within dhat = 1 mm of the edge, and neither end state is crossed
    pa, pb = np.array([0.5, 0.05]), np.array([0.5, -0.05])
    aa = ab = np.array([0.0, 0.0])
    ba = bb = np.array([1.0, 0.0])
    dhat = 1e-3
    assert point_edge_distance2(*pa, *aa, *ba) > dhat**2
    assert point_edge_distance2(*pb, *ab, *bb) > dhat**2
    assert point_edge_impact(pa, pb, aa, ab, ba, bb) == pytest.approx(0.5, rel=1e-14)
    # a moving edge: a wall tip sweeps across a still node
    t = point_edge_impact(np.array([0.5, 0.0]), np.array([0.5, 0.0]), np.array([0.0, -1.0]),
                          np.array([0.0, 1.0]), np.array([1.0, -1.0]), np.array([1.0, 1.0]))  # fmt: skip
    assert t == pytest.approx(0.5, rel=1e-14)
    # passing beside the segment's end is no impact
    assert point_edge_impact(np.array([1.5, 0.05]), np.array([1.5, -0.05]), aa, ab, ba, bb) == np.inf


def test_ccd_over_a_ring_finds_the_first_wall_crossing():
    x = _folded_ring(gap=4e-3)
    n = x.shape[0]
    moved = x.copy()
    moved[: n // 4, 1] -= 8e-3  # the top wall pushed through the bottom wall
    assert self_intersects(moved)
    model, ws, _ = _model_and_pairs(x)
    count = find_pairs(x, moved, model.rest_len[0], 1e-3, ws.barrier)
    first = impact_fraction(x, moved, ws.barrier.pairs, count)
    assert first == pytest.approx(0.5, abs=1e-12)  # top meets bottom half-way
    assert not self_intersects(x + 0.8 * first * (moved - x))


def test_a_ring_at_rest_has_no_candidate_pairs():
    scene = Scene(rings=[Ring()], gravity=0.0)
    model = build_model(scene)
    x, _ = initial_state(scene)
    ws = build_workspace(x.shape[1])
    assert find_pairs(x[0], x[0], model.rest_len[0], model.thickness[0], ws.barrier) == 0


def test_near_pairs_remembers_clear_positions_and_nothing_else():
    scene = Scene(rings=[Ring()], gravity=0.0)
    model = build_model(scene)
    x, _ = initial_state(scene)
    x = x[0].copy()
    bw = build_workspace(x.shape[0]).barrier
    rest_len, dhat = model.rest_len[0], model.thickness[0]
    assert near_pairs(x, rest_len, dhat, bw) == 0
    assert np.array_equal(bw.clear_x, x) and tuple(bw.clear_key) == (rest_len, dhat)
    squashed = x.copy()
    squashed[:, 1] = x[0, 1] + 0.02 * (x[:, 1] - x[0, 1])  # top and bottom within dhat
    near = near_pairs(squashed, rest_len, dhat, bw)
    assert near > 0 and np.array_equal(bw.clear_x, x)  # swept, and not remembered
    assert near_pairs(x, rest_len, dhat, bw) == 0
    # the remembered positions are what is compared: planted, they answer without a sweep
    bw.clear_x[:] = squashed
    assert near_pairs(squashed, rest_len, dhat, bw) == 0
    assert near_pairs(squashed, rest_len, 1.01 * dhat, bw) == near  # but only with their dhat


def test_pairs_near_along_the_ring_are_excluded():
    n, rest_len, dhat = 64, 1e-2, 2e-3
    assert excluded(10, 10, n, rest_len, dhat) and excluded(10, 9, n, rest_len, dhat)  # its own edges
    assert not excluded(10, 11, n, rest_len, dhat)  # the next edge, one rest length away
    assert excluded(10, 11, n, 1e-3, dhat)  # unless that is within the arc exclusion
    assert excluded(10, 63, n, rest_len, 0.5 * 64 * rest_len)  # within the arc exclusion
    assert not excluded(10, 40, n, rest_len, dhat)


def _within(x, rest_len, dhat):
    """The (node, edge) pairs of ``x`` within ``dhat`` that are not excluded, by brute force."""
    n = x.shape[0]
    pairs = [
        (i, j)
        for i in range(n)
        for j in range(n)
        if not excluded(i, j, n, rest_len, dhat)
        and point_edge_distance2(*x[i], *x[j], *x[(j + 1) % n]) < dhat**2
    ]
    return np.array(pairs, dtype=np.int64).reshape(-1, 2)


def _min_pair_distance(x, rest_len, dhat):
    n = x.shape[0]
    return min(
        np.sqrt(point_edge_distance2(*x[i], *x[j], *x[(j + 1) % n]))
        for i in range(n)
        for j in range(n)
        if not excluded(i, j, n, rest_len, dhat)
    )


def test_a_soft_empty_ring_comes_to_rest_folded():
    h = 2e-3
    ring = Ring(pressure=None, youngs_modulus=1e5, thickness=h, n_nodes=64, position=(0.0, 0.1005))
    scene = Scene(rings=[ring], grounds=[Ground()], damping=20.0, dt=1e-3, adaptive=True, impulse_tol=5e-3)
    traj = simulate(scene, 1.0, output_dt=0.05)
    x = traj.x[-1, 0]
    assert x[:, 1].max() < 8 * h  # squashed flat: top wall on the bottom wall
    rest_len = build_model(scene).rest_len[0]
    assert 0.0 < _min_pair_distance(x, rest_len, h) < h  # held apart by the barrier, inside dhat
    kinetic = traj.energy()["kinetic"][:, 0]
    mass = build_model(scene).node_mass[0] * 64
    assert kinetic[-4:].max() < 1e-5 * mass * 9.81 * 2 * ring.radius  # at rest
    assert not any(self_intersects(xk[0]) for xk in traj.x)
    barrier = traj.energy()["self_contact"][:, 0]
    assert barrier[0] == 0.0 and barrier[-1] > 0.0  # resting within dhat: the barrier holds it
    pairs = _within(x, rest_len, h)
    kappa = build_model(scene).ea[0] / rest_len
    assert barrier[-1] == pytest.approx(barrier_energy(x, pairs, len(pairs), kappa, h), rel=1e-12)


def test_the_energy_table_has_the_barrier_the_stepper_carries():
    ring = Ring(pressure=None, youngs_modulus=1e5, thickness=2e-3, n_nodes=32, position=(0.0, 0.1005))
    scene = Scene(rings=[ring], grounds=[Ground()], damping=20.0, dt=1e-3, adaptive=True)
    sim = Simulation(scene, output_dt=0.1)
    assert sim.advance(0.6)
    table = sim.trajectory().energy()
    assert table["self_contact"][-1, 0] > 0.0
    assert table["total"][-1, 0] == pytest.approx(sim.state.energy[0, ENERGY_TOTAL], rel=1e-12)
    assert "self_contact" not in simulate(replace(scene, self_intersection="reject"), 0.01).energy()


@pytest.mark.parametrize("thickness", [1e-3, 2e-3])
def test_a_thin_walled_empty_ring_dropped_at_15_m_s_completes(thickness):
    ring = Ring(pressure=None, thickness=thickness, velocity=(0.0, -15.0), position=(0.0, 0.12))
    scene = Scene(rings=[ring], grounds=[Ground()])
    traj = simulate(scene, 0.1, output_dt=1e-3)
    assert traj.t[-1] == pytest.approx(0.1)
    assert not any(self_intersects(xk[0]) for xk in traj.x)
    energy = traj.energy()["total"][:, 0]
    assert energy.max() <= energy[0] * (1 + 1e-9)  # the barrier is a potential: no energy made


def test_the_rolling_rings_of_figure_8_complete_with_walls_of_2_5_mm():
    # the scene library's rolling rings (figure 8) with the intended wall, h = 2.5 mm instead of
    # 5 mm: the two softest sag until top meets bottom and roll folded
    slope, radius = 0.15, 0.1
    normal = np.array([-np.sin(slope), np.cos(slope)])
    heights = []
    for modulus in (2e6, 4e6, 6e6, 8e6):
        centre = tuple((radius + 0.003) * normal)
        ring = Ring(radius=radius, thickness=2.5e-3, youngs_modulus=modulus, pressure=None, position=centre)
        scene = Scene(rings=[ring], grounds=[Ground(angle=slope, friction=0.8)], damping=20.0, dt=1e-2,
                      adaptive=True, impulse_tol=2e-3, newton_tol=1e-9, rho_infinity=0.3)  # fmt: skip
        traj = simulate(scene, 2.0, output_dt=5e-3)
        assert traj.t[-1] == pytest.approx(2.0)
        assert not any(self_intersects(xk[0]) for xk in traj.x)
        up = traj.x[:, 0] @ normal
        heights.append(np.mean(up.max(axis=1)[-100:] - up.min(axis=1)[-100:]))
    assert np.all(np.diff(heights) > 0.0)  # the rolling shape is taller the stiffer the wall
    assert heights[0] < 0.3 * 2 * radius  # the softest rolls folded


def test_the_barrier_is_stiff_enough_to_spend_the_rings_start_energy():
    """``kappa = max(EA / l0, K_0 / (dhat^2 beta(STOP_GAP^2)))``: a ring at rest keeps its edges'
    stiffness; thrown, its kinetic energy ``K_0`` is spent before a pair comes within ``STOP_GAP
    dhat``."""
    ring = Ring(pressure=None, thickness=1e-3)
    at_rest = build_model(Scene(rings=[ring]))
    assert at_rest.start_energy[0] == 0.0
    assert stiffness(at_rest, 0) == at_rest.ea[0] / at_rest.rest_len[0]
    thrown = build_model(Scene(rings=[replace(ring, velocity=(20.0, -20.0), angular_velocity=30.0)]))
    k0 = thrown.start_energy[0]
    assert k0 == pytest.approx(0.5 * total_mass(ring) * (800.0 + (30.0 * inflated_radius(ring)) ** 2))
    assert stiffness(thrown, 0) > 10.0 * stiffness(at_rest, 0)  # (61 times here)
    assert stiffness(thrown, 0) * ring.thickness**2 * beta(STOP_GAP**2) == pytest.approx(k0, rel=1e-12)


# Two thin walls thrown fast, from the soak (seed 0): scene 392, h/R = 0.006 at 30 m/s and 33 rad/s
# onto flat ground, and 1103, h/R = 0.008 and empty at 28 m/s and 49 rad/s onto an 8 degree slope.
THIN_FAST_392 = Scene(
    rings=[Ring(radius=0.2251346740756372, n_nodes=64, youngs_modulus=458156.2762226351,
                thickness=0.0013643996781591162, width=0.09523869405771865, density=1031.5075085367903,
                pressure=519.9281373067845, position=(0.0, 0.5699005690151531),
                velocity=(13.731044865271038, -27.050777403030427), angular_velocity=33.398045121902356)],
    grounds=[Ground(friction=1.4909735440943468)], contact="predictor_corrector", gravity=12.717321730575042,
    damping=0.0, rho_infinity=0.8085577370208539, dt=0.00016664823933942004, adaptive=True,
    impulse_tol=5e-3, atmospheric_pressure=0.0, gas_exponent=1.4,
)  # fmt: skip
THIN_FAST_1103 = Scene(
    rings=[Ring(radius=0.2727413811620114, n_nodes=32, youngs_modulus=222478.60937027074,
                thickness=0.002251771827540602, width=0.058159962633964904, density=262.5472196851116,
                pressure=None, position=(-0.03857997180564954, 0.27392126651429904),
                velocity=(7.750873881583246, -27.2387550442769), angular_velocity=48.91430368302153)],
    grounds=[Ground(angle=0.13992292273830773, friction=1.1276668678395967)], contact="predictor_corrector",
    gravity=5.332680929239819, damping=50.0, rho_infinity=0.9468670816202109, dt=0.004777778224637557,
    adaptive=True, impulse_tol=5e-3, atmospheric_pressure=0.0, gas_exponent=1.0,
)  # fmt: skip


@pytest.mark.parametrize(
    ("scene", "t_end", "stop"),
    [
        (THIN_FAST_392, 0.10049042430412317, "a ring's wall crossed itself"),
        (THIN_FAST_1103, 0.06485330018586018, "the step gained energy"),
    ],
    ids=["392", "1103"],
)
def test_thin_walls_thrown_fast_complete_with_the_barriers_sized_to_their_energy(scene, t_end, stop):
    """With the edges' stiffness alone (the same start given as x0, v0 to a scene whose rings are at
    rest) these runs stopped at dt_min: in 392 a node was pushed to 1e-5 of the wall thickness from
    an edge, and round-off decided whether a 1 ns step crossed it; in 1103 a fold past 150 degrees.
    With the barrier and the wall limits sized to the start energy they reach their end, every
    invariant held (no crossing, nothing below the ground, no energy made)."""
    x0, v0 = initial_state(scene)
    at_rest = replace(
        scene, rings=[replace(r, velocity=(0.0, 0.0), angular_velocity=0.0) for r in scene.rings]
    )
    weak = Simulation(at_rest, x0=x0, v0=v0)
    assert not weak.advance(t_end) and stop in weak.failure
    result = audit(scene, t_end)
    assert result.reached_end and result.problems() == [], result
    assert not any(self_intersects(xk[0]) for xk in result.traj.x)
