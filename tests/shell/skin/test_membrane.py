"""Stretching: energy against the closed form of an equibiaxial stretch; gradient and Hessian
against central differences; no energy or force in rigid motion."""

import numpy as np
import pytest

from ballenv.shell.skin.membrane import (
    lame_plane_stress,
    membrane_energy,
    membrane_gradient,
    membrane_hessians,
    rest_frames,
)

from ..conftest import assemble_dense, central_gradient, central_jacobian, relative_error, small_model


def parts(model):
    return model.triangles, model.beta, model.area, model.lam, model.mu, model.thickness, np.zeros((2, 3))


def energy(model, x):
    return membrane_energy(x, *parts(model))


def gradient(model, x):
    g = np.zeros_like(x)
    membrane_gradient(x, *parts(model), g)
    return g


def test_an_equibiaxial_stretch_stores_A_h_E_g2_over_1_minus_nu():
    model, _, _ = small_model(youngs_modulus=5e6, poisson_ratio=0.45, thickness=3e-3)
    s = 1.01
    g = (s * s - 1) / 2  # Green strain
    expected = model.area.sum() * 3e-3 * 5e6 / (1 - 0.45) * g * g
    assert energy(model, s * model.rest) == pytest.approx(expected, rel=1e-12)


def test_the_lame_constants_are_those_of_plane_stress():
    lam, mu = lame_plane_stress(5e6, 0.45)
    assert 2 * lam + 2 * mu == pytest.approx(5e6 / (1 - 0.45))  # equibiaxial modulus E / (1 - nu)
    assert mu == pytest.approx(5e6 / 2.9)


def test_rigid_motion_stores_no_energy_and_makes_no_force():
    model, _, _ = small_model()
    angle = 0.7
    rot = np.array([[np.cos(angle), -np.sin(angle), 0], [np.sin(angle), np.cos(angle), 0], [0, 0, 1]])
    x = model.rest @ rot.T + (0.3, -0.2, 1.0)
    assert energy(model, x) < 1e-20
    assert np.abs(gradient(model, x)).max() < 1e-9


def test_rest_frames_reproduce_the_rest_edges():
    model, _, _ = small_model()
    beta, area = rest_frames(model.rest, model.triangles)
    x = model.rest[model.triangles]  # (T, 3, 3)
    f = np.einsum("tac,tai->tic", x, beta)  # F's columns: an isometry of the rest plane
    assert np.allclose(np.einsum("tic,tjc->tij", f, f), np.eye(2), atol=1e-12)
    assert np.allclose(beta.sum(axis=1), 0.0, atol=1e-9)


def test_gradient_and_hessian_match_central_differences():
    model, _, x = small_model()
    assert relative_error(gradient(model, x), central_gradient(lambda y: energy(model, y), x)) < 1e-6
    mats = np.zeros((len(model.triangles), 9, 9))
    membrane_hessians(x, *parts(model), mats)
    hessian = assemble_dense(model.triangles, mats, len(x))
    assert relative_error(hessian, central_jacobian(lambda y: gradient(model, y), x)) < 1e-6
    assert np.allclose(mats, np.transpose(mats, (0, 2, 1)))
