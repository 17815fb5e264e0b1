"""Contact between shells: the point-triangle and edge-edge distances against their closed forms
and central differences, the barrier's derivatives, its positive semi-definite projection, and
head-on collisions of two balls against the conservation laws, with an independent check
(meshcheck.py) that no vertex enters the other ball and no edge crosses its skin."""

import numpy as np
import pytest

from ballenv.shell import Scene, Shell, simulate
from ballenv.shell.simulation import build
from ballenv.shell.skin.model import build_model
from ballenv.shell.step.implicit import total_energy
from ballenv.shell.touch import distance as dist
from ballenv.shell.touch.contact import pair_barrier
from ballenv.shell.touch.projection import project_psd

from ..meshcheck import check_apart, check_self

TRIANGLE = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
# a point over each of the triangle's seven features: (point, parameters of the feature, distance)
POINTS = [
    ((0.2, 0.3, 0.5), 2, 0.5),  # the face
    ((-0.3, -0.4, 0.2), 0, np.sqrt(0.09 + 0.16 + 0.04)),  # vertex a
    ((1.5, -0.2, 0.1), 0, np.sqrt(0.25 + 0.04 + 0.01)),  # vertex b
    ((-0.1, 1.6, 0.3), 0, np.sqrt(0.01 + 0.36 + 0.09)),  # vertex c
    ((0.5, -0.3, 0.4), 1, 0.5),  # edge ab
    ((-0.6, 0.5, 0.8), 1, 1.0),  # edge ac
    ((0.8, 0.8, 0.0), 1, 0.6 / np.sqrt(2.0)),  # edge bc
]
# two edges: (second edge's ends, parameters, distance); the first is (0, 0, 0) - (1, 0, 0)
EDGES = [
    (((0.5, -0.5, 0.3), (0.5, 0.5, 0.3)), 2, 0.3),  # crossing, both inside
    (((1.4, -0.5, 0.3), (1.4, 0.5, 0.3)), 1, 0.5),  # beyond the first edge's end
    (((1.3, 0.4, 0.0), (2.0, 0.4, 0.0)), 0, 0.5),  # end to end
]


def central(f, x, eps=1e-6):
    out = []
    flat = x.reshape(-1)
    for k in range(flat.size):
        xp, xm = flat.copy(), flat.copy()
        xp[k] += eps
        xm[k] -= eps
        out.append((f(xp.reshape(x.shape)) - f(xm.reshape(x.shape))) / (2 * eps))
    return np.array(out)


def check_derivatives(pos, kind):
    d2, g, h, _ = dist.pair_derivatives(pos, kind)
    g_fd = central(lambda p: dist.pair_derivatives(p, kind)[0], pos)
    h_fd = central(lambda p: dist.pair_derivatives(p, kind)[1], pos).T
    assert np.abs(g - g_fd).max() <= 1e-8 * np.abs(g).max()
    assert np.abs(h - h_fd).max() <= 1e-7 * np.abs(h).max()


@pytest.mark.parametrize(("point", "parameters", "distance"), POINTS)
def test_point_triangle_distance_matches_the_closed_form_and_central_differences(point, parameters, distance):
    pos = np.vstack([point, TRIANGLE])
    d2, _, _, k = dist.pair_derivatives(pos, dist.POINT_TRIANGLE)
    assert k == parameters
    assert np.sqrt(d2) == pytest.approx(distance, rel=1e-14)
    rng = np.random.default_rng(parameters)
    check_derivatives(pos + 0.02 * rng.standard_normal((4, 3)), dist.POINT_TRIANGLE)


@pytest.mark.parametrize(("second", "parameters", "distance"), EDGES)
def test_edge_edge_distance_matches_the_closed_form_and_central_differences(second, parameters, distance):
    pos = np.vstack([[(0.0, 0.0, 0.0), (1.0, 0.0, 0.0)], second])
    d2, _, _, k = dist.pair_derivatives(pos, dist.EDGE_EDGE)
    assert k == parameters
    assert np.sqrt(d2) == pytest.approx(distance, rel=1e-14)
    rng = np.random.default_rng(parameters)
    check_derivatives(pos + 0.02 * rng.standard_normal((4, 3)), dist.EDGE_EDGE)


def barrier_cases():
    """Pairs within dhat = 1 mm of each kind and feature, and near-parallel edges (mollified)."""
    gap = 6e-4  # m: the configurations above, scaled to this distance
    cases = [(np.vstack([p, TRIANGLE]) * (gap / d), dist.POINT_TRIANGLE) for p, _, d in POINTS]
    for second, _, d in EDGES:
        cases.append((np.vstack([[(0, 0, 0), (1, 0, 0)], second]) * (gap / d), dist.EDGE_EDGE))
    slope = 0.022  # rad: |e_1 x e_2|^2 half the mollifier's eps
    ends = [(0, 0, 0), (1e-2, 0, 0), (2e-3, -3e-3 * slope, 3e-4), (9e-3, 4e-3 * slope, 3e-4)]
    cases.append((np.array(ends, dtype=float), dist.EDGE_EDGE))
    return cases


@pytest.mark.parametrize(("pos", "kind"), barrier_cases())
def test_the_barrier_gradient_and_hessian_match_central_differences(pos, kind):
    rng = np.random.default_rng(3)
    pos = pos + 1e-5 * rng.standard_normal((4, 3))
    rest = pos.copy()
    kappa, dhat = 1.5e4, 1e-3

    def energy(p):
        return pair_barrier(p, kind, kappa, dhat, rest, False)[0]

    b, g, h = pair_barrier(pos, kind, kappa, dhat, rest, False)
    assert b > 0.0
    g_fd = central(energy, pos, eps=1e-9)
    h_fd = central(lambda p: pair_barrier(p, kind, kappa, dhat, rest, False)[1], pos, eps=1e-9).T
    assert np.abs(g - g_fd).max() <= 1e-5 * np.abs(g).max()
    assert np.abs(h - h_fd).max() <= 1e-5 * np.abs(h).max()


def test_the_projection_is_the_nearest_positive_semi_definite_matrix():
    rng = np.random.default_rng(4)
    a = rng.standard_normal((12, 12))
    a = a + a.T
    lam, q = np.linalg.eigh(a)
    projected, vecs, scratch = a.copy(), np.zeros((12, 12)), np.zeros(12)
    lowest = project_psd(projected, vecs, scratch)
    assert lowest == pytest.approx(lam.min(), rel=1e-12)
    np.testing.assert_allclose(projected, (q * np.maximum(lam, 0.0)) @ q.T, atol=1e-12 * np.abs(a).max())


def test_self_contact_is_validated():
    with pytest.raises(ValueError, match="self_contact"):
        Scene(self_contact=1)


def head_on(closing_speed, t_end):
    """Two default balls 1.4 cm apart flying at each other along x without gravity."""
    half = closing_speed / 2
    shells = [
        Shell(position=(-0.135, 0, 0), velocity=(half, 0, 0)),
        Shell(position=(0.135, 0, 0), velocity=(-half, 0, 0)),
    ]
    scene = Scene(shells=shells, gravity=0.0)
    return scene, simulate(scene, t_end)


def check_collision(scene, traj, closing_speed):
    """The conservation laws and intersection-freeness of a head-on collision (module doc)."""
    _, steps = build(scene)
    mass = steps[0].problem.model.mass
    triangles = steps[0].problem.model.triangles
    momentum = np.einsum("i,tsik->tk", mass, traj.v)
    one_ball = mass.sum() * closing_speed / 2
    assert np.abs(momentum).max() <= 1e-10 * one_ball  # zero to round-off and Newton's tolerance
    velocity = np.einsum("i,sik->sk", mass, traj.v[-1]) / mass.sum()
    np.testing.assert_allclose(velocity[0], -velocity[1], atol=1e-10 * closing_speed)
    assert velocity[0, 0] < -0.5 * closing_speed / 2  # they bounced apart
    for t in range(len(traj.t)):
        centres = traj.x[t].mean(axis=1)
        radii = np.linalg.norm(traj.x[t] - centres[:, None], axis=2).max(axis=1)
        if np.linalg.norm(centres[0] - centres[1]) > radii.sum():
            continue  # their bounding spheres are apart
        winding, crossings, low = check_apart(traj.x[t, 0], traj.x[t, 1], triangles)
        assert winding < 0.5 and crossings == 0 and low > 0.0
    low_end = check_apart(traj.x[-1, 0], traj.x[-1, 1], triangles)[2]
    assert low_end > scene.contact_distance  # apart: no barrier energy left at the end
    energy = [
        sum(total_energy(st, traj.x[t, k], traj.v[t, k]) for k, st in enumerate(steps)) for t in (0, -1)
    ]
    assert energy[1] <= energy[0]


def test_two_balls_colliding_head_on_at_4_m_per_s_conserve_momentum_and_never_intersect():
    scene, traj = head_on(4.0, 0.05)
    check_collision(scene, traj, 4.0)


def test_two_balls_colliding_at_20_m_per_s_conserve_momentum_and_never_intersect():
    scene, traj = head_on(20.0, 0.03)
    assert np.all(np.isfinite(traj.x))
    check_collision(scene, traj, 20.0)


def test_shells_far_apart_step_as_each_would_alone():
    a = Shell(position=(0, 0, 0), velocity=(1.0, 0, 0))
    b = Shell(position=(1.0, 0, 0), velocity=(1.0, 0.5, 0))
    common = {"gravity": 0.0, "adaptive": False, "dt": 1e-3}
    both = simulate(Scene(shells=[a, b], **common), 0.02)
    for k, shell in enumerate((a, b)):
        alone = simulate(Scene(shells=[shell], **common), 0.02)
        assert np.array_equal(both.x[:, k], alone.x[:, 0])


def collapse(self_contact):
    """A ball at 80 kPa below the atmosphere (far beyond its buckling pressure, about 4 kPa), from
    its rest sphere with its top pushed in: it crumples until the gas is back near atmospheric
    pressure, about a fifth of its volume, pressing its inverted top onto the rest of its skin."""
    shell = Shell(pressure=-80e3, position=(0, 0, 0))
    x0 = build_model(shell).rest
    v0 = np.zeros_like(x0)
    v0[:, 2] = -2.0 * np.clip(x0[:, 2] / shell.radius, 0.0, None) ** 4
    scene = Scene(shells=[shell], gravity=0.0, damping=50.0, self_contact=self_contact)
    return simulate(scene, 0.03, x0=x0[None], v0=v0[None]), build_model(shell).triangles


@pytest.mark.slow
def test_a_collapsing_ball_with_self_contact_never_passes_its_skin_through_itself():
    traj, triangles = collapse(True)
    checks = [check_self(x, triangles) for x in traj.x[:, 0]]
    assert all(crossings == 0 and low > 0.0 for crossings, low in checks)
    assert min(low for _, low in checks) < 1e-3  # opposite sides came within dhat: the barrier acted
    without, _ = collapse(False)
    assert max(check_self(x, triangles)[0] for x in without.x[::10, 0]) > 0  # it does cross itself


@pytest.mark.parametrize(("pos", "kind"), barrier_cases())
def test_the_barrier_hessian_is_projected_to_the_nearest_positive_semi_definite_matrix(pos, kind):
    kappa, dhat = 1.5e4, 1e-3
    _, _, h = pair_barrier(pos, kind, kappa, dhat, pos, False)
    _, _, projected = pair_barrier(pos, kind, kappa, dhat, pos, True)
    lam, q = np.linalg.eigh(h)
    np.testing.assert_allclose(projected, (q * np.maximum(lam, 0.0)) @ q.T, atol=1e-9 * lam.max())
