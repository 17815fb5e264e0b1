"""The self-contact barrier's wall limits (fold and collapse): their energy against the closed form,
force and Jacobian against finite differences, support, and the motion filter."""

import math

import numpy as np
import pytest

from ballenv.physics import Ground, Ring, Scene, simulate
from ballenv.physics.base.linalg import band_to_dense
from ballenv.physics.build import build_workspace
from ballenv.physics.walls.impulses import self_intersects
from ballenv.physics.walls.self_barrier import CCD_SAFETY, beta
from ballenv.physics.walls.wall_limits import (
    COLLAPSE_ON,
    FOLD_ON,
    FOLD_U,
    SHRINK_FLOOR,
    STOP_Y,
    collapse_stiffness,
    fold_stiffness,
    limit_fraction,
    wall_limit_energy,
    wall_limit_force,
    wall_limit_jacobian,
)

EA, REST = 2e3, 0.02  # N, m
SHARP = math.radians(170.0)  # rad


def _circle(n=12, radius=0.04):
    a = 2 * np.pi * np.arange(n) / n
    return np.column_stack([radius * np.cos(a), radius * np.sin(a)])


def _folded(n=12, turn=SHARP, short=0.3 * COLLAPSE_ON):
    """A circle with node 1's turning angle ``turn`` (rad, node 2 swung about node 1) and edge
    (5, 6) shortened to ``short`` of the rest length."""
    x = _circle(n)
    e1 = x[1] - x[0]
    c, s = math.cos(turn), math.sin(turn)
    e2 = np.array([c * e1[0] - s * e1[1], s * e1[0] + c * e1[1]]) / np.linalg.norm(e1) * REST
    x[2] = x[1] + e2
    mid = 0.5 * (x[5] + x[6])
    d = (x[6] - x[5]) / np.linalg.norm(x[6] - x[5]) * short * REST
    x[5], x[6] = mid - d / 2, mid + d / 2
    return x


def _turn(x, i):
    n = x.shape[0]
    e1, e2 = x[i] - x[i - 1], x[(i + 1) % n] - x[i]
    return math.atan2(e1[0] * e2[1] - e1[1] * e2[0], e1 @ e2)


def _closed_form(x):
    """``sum_i k_f beta((1 + cos phi_i) / u_on) + sum_edges k_c beta(L^2 / s^2)`` over the terms
    within their limits' reach."""
    n = x.shape[0]
    total = 0.0
    for i in range(n):
        y = (1 + math.cos(_turn(x, i))) / FOLD_U
        total += fold_stiffness(EA, REST, 0.0) * beta(y) if y < 1 else 0.0
        y = np.sum((x[(i + 1) % n] - x[i]) ** 2) / (COLLAPSE_ON * REST) ** 2
        total += collapse_stiffness(EA, REST, 0.0) * beta(y) if y < 1 else 0.0
    return total


@pytest.mark.parametrize("turn", [math.radians(170.0), math.radians(-149.0), math.radians(-178.0)])
def test_energy_is_the_closed_form(turn):
    x = _folded(turn=turn)
    assert wall_limit_energy(x, REST, EA, 0.0) > 0.0
    assert wall_limit_energy(x, REST, EA, 0.0) == pytest.approx(_closed_form(x), rel=1e-12)
    # k_f = 2 u_on EA l0, k_c = EA COLLAPSE_ON^2 l0
    assert fold_stiffness(EA, REST, 0.0) == pytest.approx(2 * (1 + math.cos(FOLD_ON)) * EA * REST)
    assert collapse_stiffness(EA, REST, 0.0) == pytest.approx(EA * COLLAPSE_ON**2 * REST)


def test_a_start_energy_the_wall_cannot_spend_raises_both_stiffnesses():
    """k_f = 2 u_on EA l0 = 10.7 J and k_c = EA s^2 / l0 = 2.5 J here; a start energy K_0 above what
    they spend at y = STOP_Y sets k = K_0 / beta(STOP_Y): K_0 is spent exactly there."""
    assert fold_stiffness(EA, REST, 1.0) == fold_stiffness(EA, REST, 0.0)  # the wall's own, stiffer
    assert collapse_stiffness(EA, REST, 1.0) == collapse_stiffness(EA, REST, 0.0)
    for k0 in (1e2, 1e4):
        assert fold_stiffness(EA, REST, k0) * beta(STOP_Y) == pytest.approx(k0, rel=1e-12)
        assert collapse_stiffness(EA, REST, k0) * beta(STOP_Y) == pytest.approx(k0, rel=1e-12)
    x = _folded(turn=math.radians(170.0))
    assert wall_limit_energy(x, REST, EA, 1e4) > 100.0 * wall_limit_energy(x, REST, EA, 0.0)


def test_no_energy_away_from_the_limits():
    assert wall_limit_energy(_circle(), REST, EA, 0.0) == 0.0  # a rest shape is untouched
    x = _folded(turn=FOLD_ON - 0.01, short=1.01 * COLLAPSE_ON)
    assert max(abs(_turn(x, i)) for i in range(12)) < FOLD_ON  # (node 1's the sharpest)
    assert wall_limit_energy(x, REST, EA, 0.0) == 0.0


def test_energy_grows_without_bound_at_both_limits():
    a = [wall_limit_energy(_folded(turn=math.pi - t, short=1.0), REST, EA, 0.0) for t in (1e-1, 1e-3, 1e-6)]
    b = [wall_limit_energy(_folded(turn=0.3, short=s), REST, EA, 0.0) for s in (1e-1, 1e-3, 1e-6)]
    assert 0.0 < a[0] < a[1] < a[2] and 0.0 < b[0] < b[1] < b[2]
    assert wall_limit_energy(_folded(turn=0.3, short=0.0), REST, EA, 0.0) == math.inf


def _force(x):
    f = np.zeros_like(x)
    wall_limit_force(x, REST, EA, 0.0, f)
    return f.ravel()


@pytest.mark.parametrize("turn", [math.radians(170.0), math.radians(-178.0)])
def test_force_and_jacobian_match_finite_differences(turn):
    x = _folded(turn=turn)
    n = x.shape[0]
    eps = 1e-9
    g_fd = np.zeros(2 * n)
    j_fd = np.zeros((2 * n, 2 * n))
    for k in range(2 * n):
        dx = np.zeros(2 * n)
        dx[k] = eps
        plus, minus = x + dx.reshape(n, 2), x - dx.reshape(n, 2)
        g_fd[k] = -(wall_limit_energy(plus, REST, EA, 0.0) - wall_limit_energy(minus, REST, EA, 0.0)) / (
            2 * eps
        )
        j_fd[:, k] = -(_force(plus) - _force(minus)) / (2 * eps)
    f = _force(x)
    assert np.abs(f).max() > 0.0
    np.testing.assert_allclose(f, g_fd, atol=1e-6 * np.abs(g_fd).max())
    ws = build_workspace(n)
    ws.band[:] = 0.0
    wall_limit_jacobian(x, REST, EA, 0.0, 1.0, ws.band, ws.pos)
    dense = band_to_dense(ws.band, ws.pos)
    np.testing.assert_allclose(dense, j_fd, atol=1e-6 * np.abs(j_fd).max())
    np.testing.assert_allclose(dense, dense.T, atol=1e-9 * np.abs(dense).max())


def test_the_filter_leaves_ordinary_motions_whole():
    x = _circle()
    rng = np.random.default_rng(0)
    assert limit_fraction(x, x + rng.normal(scale=1e-3, size=x.shape)) == 1.0
    assert limit_fraction(x, 2.0 * x + 0.5) == 1.0  # growing and moving


def test_the_filter_stops_a_node_folding_through():
    x = _folded(turn=math.radians(175.0), short=1.0)
    y = _folded(turn=math.radians(-175.0), short=1.0)  # node 2 swung through the fold to the other side
    # node 2 moves on the straight line between the two: antiparallel edges at the midpoint
    assert limit_fraction(x, y) == pytest.approx(CCD_SAFETY * 0.5, rel=1e-9)
    assert limit_fraction(x, x + 0.2 * (y - x)) == 1.0


def test_the_filter_stops_an_edge_collapsing():
    x = _circle()
    y = x.copy()
    y[6] = x[5]  # edge (5, 6) shrinks to nothing over the motion
    t = 1.0 - SHRINK_FLOOR  # |e(t)| = (1 - t) |e|
    assert limit_fraction(x, y) == pytest.approx(CCD_SAFETY * t, rel=1e-9)


def _wall_shape(traj):
    """Sharpest turning angle (rad) and shortest edge (fraction of l0) over a ring's recorded states."""
    ring = traj.scene.rings[0]
    rest = 2 * ring.radius * math.sin(math.pi / ring.n_nodes)
    x = traj.x[:, 0]
    e = np.roll(x, -1, axis=1) - x
    ep = np.roll(e, 1, axis=1)
    cross = ep[..., 0] * e[..., 1] - ep[..., 1] * e[..., 0]
    turn = np.abs(np.arctan2(cross, (ep * e).sum(-1)))
    return float(turn.max()), float(np.linalg.norm(e, axis=-1).min() / rest)


# Two random scenes of the soak that stopped at dt_min: an edge collapsed to 6e-7 of its rest length
# ("a ring's wall crossed itself"), and a node folded to 179.9998 degrees (contact impulse above
# impulse_tol). With the wall limits both reach their end.
COLLAPSING = Scene(
    rings=[Ring(radius=0.1954, n_nodes=64, youngs_modulus=6.388e5, thickness=0.05183, width=0.07768,
                density=1224.0, pressure=24582.0, position=(0.0, 0.2535), velocity=(-29.29, -26.86),
                angular_velocity=-47.68)],
    grounds=[Ground(friction=1.146)], contact="mass_modification", gravity=6.386, damping=50.0,
    integrator="backward_euler", dt=1.962e-3, adaptive=False, atmospheric_pressure=0.0,
)  # fmt: skip
FOLDING = Scene(
    rings=[Ring(radius=0.2215, n_nodes=16, youngs_modulus=1.686e5, thickness=0.01046, width=0.07008,
                density=2068.0, pressure=971.9, position=(0.0, 0.3419), velocity=(18.55, -21.0),
                angular_velocity=-1.783)],
    grounds=[Ground(friction=1.233)], contact="predictor_corrector", gravity=5.034, damping=50.0,
    integrator="backward_euler", dt=1.133e-3, adaptive=True, impulse_tol=5e-3, atmospheric_pressure=0.0,
    gas_exponent=1.4,
)  # fmt: skip


@pytest.mark.parametrize(
    ("scene", "t_end"), [(COLLAPSING, 0.0726), (FOLDING, 0.131)], ids=["collapse", "fold"]
)
def test_hard_impacts_that_collapsed_or_folded_the_wall_complete(scene, t_end):
    traj = simulate(scene, t_end)  # every step: the solver's states, not interpolated records
    assert traj.t[-1] == pytest.approx(t_end)
    assert not any(self_intersects(xk[0]) for xk in traj.x)
    turn, shortest = _wall_shape(traj)
    assert turn < math.pi and shortest > 0.0
    assert turn > FOLD_ON or shortest < COLLAPSE_ON  # a limit acted
    energy = traj.energy()
    total = energy["total"][:, 0]
    assert total.max() <= total[0] + 1e-9 * sum(abs(energy[k][0, 0]) for k in energy if k != "total")
