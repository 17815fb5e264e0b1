"""Friction on a moving surface: the slip is taken relative to the surface's slide, so a vertex
carried along by a belt feels no friction, one held still is dragged at Coulomb's mu lambda, and
the work through the slide is that force times the slide."""

import numpy as np
import pytest

from ballenv.shell.touch import friction

TILTED = np.array([[0.0, 0.6, 0.8]])
MU = np.array([0.5])
LAM = np.array([[4.0]])  # N
E = 1e-6  # m: eps_v h


def along_plane(v):
    """``v`` less its part along the tilted normal."""
    n = TILTED[0]
    return v - (v @ n) * n


def forces(x, x0, slide):
    grad, blocks = np.zeros((1, 3)), np.zeros((1, 3, 3))
    friction.add_friction(x, x0, TILTED, slide, LAM, MU, E, grad, blocks, np.zeros(3))
    return -grad[0]


def test_a_vertex_moving_with_the_belt_does_not_slip_and_one_held_still_is_dragged_along():
    x0 = np.array([[0.1, 0.2, 0.3]])
    slide = along_plane(np.array([1e-3, -2e-3, 0.0]))[None]  # m over the step
    with_belt = x0 + slide + 5e-4 * TILTED  # and away from the plane: no slip
    assert np.allclose(forces(with_belt, x0, slide), 0.0, atol=1e-9)  # of the 2 N Coulomb force: round-off
    assert friction.friction_energy(with_belt, x0, TILTED, slide, LAM, MU, E, np.zeros(3)) == pytest.approx(
        MU[0] * LAM[0, 0] * E / 3
    )
    held = forces(x0, x0, slide)  # the surface slides under it: Coulomb's force along the slide
    direction = slide[0] / np.linalg.norm(slide[0])
    assert np.allclose(held, MU[0] * LAM[0, 0] * direction, rtol=1e-12)
    work = friction.friction_work(x0, x0, TILTED, slide, LAM, MU, E, np.zeros(3))
    assert work == pytest.approx(held @ slide[0]) and work == pytest.approx(
        MU[0] * LAM[0, 0] * np.linalg.norm(slide)
    )


def test_on_a_fixed_surface_friction_does_no_work():
    x0 = np.array([[0.1, 0.2, 0.3]])
    x = x0 + np.array([[1e-3, 0.0, 0.0]])
    assert friction.friction_work(x, x0, TILTED, np.zeros((1, 3)), LAM, MU, E, np.zeros(3)) == 0.0
