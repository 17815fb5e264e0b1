"""Bending: the dihedral angle of a fold; the constant against Kirchhoff-Love on a lattice bent into
quadratic surfaces; gradient and Hessian against central differences; rigid-motion invariance."""

import numpy as np
import pytest

from ballenv.shell.skin.bending import bending_energy, bending_gradient, bending_hessians, rest_hinges
from ballenv.shell.skin.mesh import icosphere

from ..conftest import assemble_dense, central_gradient, central_jacobian, relative_error, small_model


def energy(model, x, kb=None):
    kb = model.kb if kb is None else kb
    return bending_energy(x, model.hinges, model.theta0, model.weight, kb)


def gradient(model, ws, x):
    g = np.zeros_like(x)
    bending_gradient(x, model.hinges, model.theta0, model.weight, model.kb, ws.scratch, g)
    return g


@pytest.mark.parametrize("phi", [0.3, -0.5, 2.5])
def test_the_angle_of_a_fold_is_the_turn_of_the_normal(phi):
    # triangles (x0, x1, x2) and (x0, x3, x1) flat with normal +z; x3 turned by phi about the edge,
    # down (away from the normal) for phi > 0
    x = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -np.cos(phi), -np.sin(phi)]], dtype=float)
    theta, weight = rest_hinges(x, np.array([[0, 1, 2, 3]]))
    assert theta[0] == pytest.approx(phi, abs=1e-14)
    assert weight[0] == pytest.approx(1.0 / (2 * (0.5 + 0.5)))  # l^2 / (2 (A1 + A2))


def test_a_sphere_bends_away_from_its_outward_normals():
    theta, _ = rest_hinges(icosphere(2).vertices, icosphere(2).hinges)
    assert np.all(theta > 0)


def lattice(n=40):
    """Equilateral triangles (unit edges) in the plane z = 0, outward +z; hinges of inner edges."""
    index = np.arange(n * n).reshape(n, n)
    x = np.array([(i + 0.5 * j, j * np.sqrt(3) / 2, 0.0) for j in range(n) for i in range(n)])
    tri = []
    for j in range(n - 1):
        for i in range(n - 1):
            tri += [
                (index[j, i], index[j, i + 1], index[j + 1, i]),
                (index[j, i + 1], index[j + 1, i + 1], index[j + 1, i]),
            ]
    opposite = {(t[m], t[(m + 1) % 3]): t[(m + 2) % 3] for t in tri for m in range(3)}
    hinges = np.array(
        [(i, j, k, opposite[(j, i)]) for (i, j), k in opposite.items() if i < j and (j, i) in opposite]
    )
    return x, hinges


@pytest.mark.parametrize(
    "curvature",
    [[[1, 0], [0, 0]], [[0, 0], [0, 1]], [[1, 0], [0, 1]], [[0, 1], [1, 0]], [[0.3, 0.7], [0.7, -0.2]]],
)
def test_the_hinge_energy_per_area_of_a_quadratic_surface_is_kb_over_2_tr2_minus_8_thirds_det(curvature):
    x, hinges = lattice()
    k = 1e-5 * np.array(curvature, dtype=float)
    bent = x.copy()
    bent[:, 2] = 0.5 * np.einsum("ij,jk,ik->i", x[:, :2], k, x[:, :2])
    theta0, weight = rest_hinges(x, hinges)
    theta, _ = rest_hinges(bent, hinges)
    middle = np.all(np.abs(x[hinges[:, 0], :2] - x[:, :2].mean(axis=0)) < 10, axis=1)
    area = middle.sum() / (6 / np.sqrt(3))  # 6 / sqrt(3) edges per unit area
    per_area = (weight * (theta - theta0) ** 2)[middle].sum() / area  # per unit k_b
    expected = 0.5 * (np.trace(k) ** 2 - 8 / 3 * np.linalg.det(k))
    assert per_area == pytest.approx(expected, rel=1e-4)


def test_rigid_motion_stores_no_energy_and_makes_no_force():
    model, ws, _ = small_model()
    angle = 1.1
    rot = np.array([[1, 0, 0], [0, np.cos(angle), -np.sin(angle)], [0, np.sin(angle), np.cos(angle)]])
    x = model.rest @ rot.T + (1.0, 2.0, -0.5)
    assert energy(model, x) < 1e-24
    assert np.abs(gradient(model, ws, x)).max() < 1e-12


def test_gradient_and_hessian_match_central_differences():
    model, ws, x = small_model()
    assert relative_error(gradient(model, ws, x), central_gradient(lambda y: energy(model, y), x)) < 1e-6
    bending_hessians(x, model.hinges, model.theta0, model.weight, model.kb, ws.scratch, ws.hinge_hess)
    hessian = assemble_dense(model.hinges, ws.hinge_hess, len(x))
    fd = central_jacobian(lambda y: gradient(model, ws, y), x)
    assert relative_error(hessian, fd) < 1e-6
    assert np.allclose(
        ws.hinge_hess,
        np.transpose(ws.hinge_hess, (0, 2, 1)),
        rtol=0,
        atol=1e-12 * np.abs(ws.hinge_hess).max(),
    )
