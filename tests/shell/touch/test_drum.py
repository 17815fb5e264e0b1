"""The drums' barrier: its derivatives against central differences inside and outside a tilted
cylinder, the sign of its curvature term and its positive part, its reach and wall, the exact
straight-motion limit against the line-cylinder intersection, and the turning surface's friction
and its work against the closed forms."""

import math

import numpy as np
import pytest

from ballenv.shell import Drum
from ballenv.shell.touch import drum, drum_friction
from ballenv.shell.touch.turning import Turning

AXIS = np.array([1.0, 2.0, 2.0]) / 3.0  # a unit axis
CENTRE = np.array([0.1, -0.2, 0.3])
RADIUS = 0.5
DHAT, KAPPA = 1e-3, 1e4


def record(inside, friction=0.0):
    """One tilted drum's record for a single vertex."""
    d = Drum(RADIUS, tuple(CENTRE), tuple(AXIS), inside=inside, friction=friction)
    return drum.make_drums([d], 1)


def vertex_at(gap, inside, along=0.07):
    """A vertex ``gap`` (m) off the drum's surface, ``along`` (m) down its axis."""
    radial = np.cross(AXIS, [0.0, 0.0, 1.0])
    radial /= np.linalg.norm(radial)
    rho = RADIUS - gap if inside else RADIUS + gap
    return (CENTRE + along * AXIS + rho * radial)[None, :]


def energy(x, dr):
    return drum.barrier_energy(np.ascontiguousarray(x), dr, DHAT, KAPPA)


def gradient(x, dr, project=False):
    g, b = np.zeros((1, 3)), np.zeros((1, 3, 3))
    drum.add_barrier(np.ascontiguousarray(x), dr, DHAT, KAPPA, g, b, project)
    return g, b


@pytest.mark.parametrize("inside", [True, False])
@pytest.mark.parametrize("gap", [0.0002, 0.0005, 0.0009])
def test_barrier_derivatives_match_central_differences(inside, gap):
    dr, eps = record(inside), 1e-8
    x = vertex_at(gap, inside)
    grad, blocks = gradient(x, dr)
    size = np.abs(grad).max()  # the energy's round-off in d (1e-16 m) is 1e-8 of it at this eps
    for a in range(3):
        e = np.zeros((1, 3))
        e[0, a] = eps
        central = (energy(x + e, dr) - energy(x - e, dr)) / (2 * eps)
        assert grad[0, a] == pytest.approx(central, rel=1e-6, abs=1e-7 * size)
        column = (gradient(x + e, dr)[0] - gradient(x - e, dr)[0])[0] / (2 * eps)
        assert np.allclose(blocks[0, :, a], column, rtol=1e-5, atol=1e-6 * np.abs(blocks).max())
    # the force pushes back toward the allowed side: inward inside, outward outside
    outward = (x[0] - CENTRE) - ((x[0] - CENTRE) @ AXIS) * AXIS
    assert (grad[0] @ outward > 0) == inside
    lam = np.zeros((1, 1))
    drum.normal_forces(x, dr, DHAT, KAPPA, lam)
    assert lam[0, 0] == pytest.approx(np.linalg.norm(grad[0]))


@pytest.mark.parametrize("inside", [True, False])
def test_the_curvature_term_is_indefinite_only_outside_and_its_positive_part_is_kept(inside):
    dr = record(inside)
    x = vertex_at(0.0004, inside)
    exact = np.linalg.eigvalsh(gradient(x, dr)[1][0])
    kept = gradient(x, dr, project=True)[1][0]
    assert (exact.min() < -1e-6 * exact.max()) == (not inside)
    assert np.linalg.eigvalsh(kept).min() >= -1e-9 * exact.max()
    if inside:
        assert np.allclose(kept, gradient(x, dr)[1][0])
    else:  # only the tangential curvature -|B'| / rho is dropped: the radial stiffness stays
        assert np.linalg.eigvalsh(kept).max() == pytest.approx(exact.max())


def test_the_barrier_acts_only_within_dhat_and_walls_off_the_surface():
    for inside in (True, False):
        dr = record(inside)
        assert energy(vertex_at(0.0011, inside), dr) == 0.0
        assert energy(vertex_at(-0.002, inside), dr) == math.inf
        assert drum.min_distance(vertex_at(0.004, inside), dr) == pytest.approx(0.004)


@pytest.mark.parametrize("inside", [True, False])
def test_a_straight_motion_stops_where_the_line_meets_the_shrunk_cylinder(inside):
    dr = record(inside)
    gap = 0.01
    x = vertex_at(gap, inside)
    rng = np.random.default_rng(1)
    toward = (CENTRE - x[0]) if not inside else (x[0] - CENTRE)
    for _ in range(5):
        dx = (0.05 * toward + 0.02 * rng.standard_normal(3))[None, :]
        alpha = drum.max_step(x, dx, dr)
        limit = RADIUS - gap * (1 - drum.CCD_SAFETY) if inside else RADIUS + gap * (1 - drum.CCD_SAFETY)
        s = np.linspace(0.0, min(alpha, 1.0), 2001)
        p = x[0] + s[:, None] * dx[0] - CENTRE
        rho = np.linalg.norm(p - np.outer(p @ AXIS, AXIS), axis=1)
        assert np.all((rho <= limit * (1 + 1e-12)) if inside else (rho >= limit * (1 - 1e-12)))
        if alpha < 1.0:  # the bound is the crossing itself, not a cautious guess
            assert rho[-1] == pytest.approx(limit, rel=1e-9)
    away = (x[0] - CENTRE) * (-1 if inside else 1)
    assert drum.max_step(x, 1e-3 * away[None, :], dr) == 1.0


def test_friction_slips_against_the_turning_surface():
    """A vertex on the inside of a turning drum that does not move slips by ``-theta a x r``; one
    carried along with the surface does not slip, so it feels no force and the drum does no work."""
    dr = record(True, friction=0.5)
    x0 = vertex_at(0.0004, True)
    drum.normal_forces(x0, dr, DHAT, KAPPA, dr.lam)
    lam = dr.lam[0, 0]
    assert lam > 0
    theta, e = 1e-3, 1e-6
    dr.turn[:] = theta
    r = x0[0] - CENTRE
    slide = theta * np.cross(AXIS, r)
    grad, blocks = np.zeros((1, 3)), np.zeros((1, 3, 3))
    drum_friction.add_friction(x0, x0, dr, e, grad, blocks)
    # held still, Coulomb's force mu lambda along the slide
    assert grad[0] == pytest.approx(-0.5 * lam * slide / np.linalg.norm(slide), rel=1e-9)
    work = drum_friction.friction_work(x0, x0, dr, e)
    assert work == pytest.approx(0.5 * lam * np.linalg.norm(slide), rel=1e-9)
    assert drum_friction.friction_energy(x0, x0, dr, e) == pytest.approx(0.5 * lam * np.linalg.norm(slide))
    carried = x0 + slide[None, :]
    g = np.zeros((1, 3))
    drum_friction.add_friction(carried, x0, dr, e, g, np.zeros((1, 3, 3)))
    assert np.allclose(g, 0.0, atol=1e-9 * lam)  # the slip's round-off (1e-16 m) over e = 1e-6 m
    assert drum_friction.friction_work(carried, x0, dr, e) == pytest.approx(0.0, abs=1e-9 * work)


def test_the_turn_over_a_step_integrates_the_spin_up():
    drums = [Drum(angular_velocity=2.0, spin_up=0.5), Drum(angular_velocity=-3.0)]
    turning = Turning(drums, np.zeros(2))
    turning.prepare(0.4, 0.2)  # across the end of the spin-up
    first = 2.0 * (0.5**2 - 0.4**2) / (2 * 0.5) + 2.0 * 0.1
    assert turning.turn == pytest.approx([first, -0.6])
    assert turning.angular_velocities(0.25) == pytest.approx([1.0, -3.0])
