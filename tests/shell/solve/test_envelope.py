"""The envelope Cholesky with Sherman-Morrison, and Jacobi-preconditioned CG on the block-sparse
operator, against a dense solve of the same system (fixed degrees of freedom, a diagonal and the
rank-one gas term included); the block-sparse product against the dense matrix."""

import numpy as np
import pytest

from ballenv.shell.skin import potential
from ballenv.shell.solve import blocks, cg, envelope

from ..conftest import assemble_dense, small_model


@pytest.fixture(scope="module")
def system():
    model, ws, x = small_model(subdivisions=2, pressure=1e3, gas_exponent=1.4)
    x = 1.01 * model.rest
    s = potential.hessian(model, ws, x)
    free = np.ones(x.shape, dtype=np.bool_)
    free[0] = False
    free[7, 1:] = False
    diagonal = np.repeat(model.mass[:, None], 3, axis=1) * 1e4
    rhs = np.random.default_rng(0).standard_normal(x.shape)
    n = x.size
    dense = assemble_dense(model.triangles, ws.tri_hess, len(x)) + assemble_dense(
        model.hinges, ws.hinge_hess, len(x)
    )
    u = ws.dvol.reshape(-1)
    dense += s * np.outer(u, u) + np.diag(diagonal.reshape(-1))
    f = free.reshape(-1)
    exact = np.zeros(n)
    exact[f] = np.linalg.solve(dense[np.ix_(f, f)], rhs.reshape(-1)[f])
    return model, ws, s, free, diagonal, rhs, exact.reshape(x.shape)


def test_the_ordering_is_a_permutation_and_narrows_the_envelope():
    model, _, _ = small_model(subdivisions=3)
    env = envelope.build_envelope(len(model.rest), model.triangles, model.hinges)
    assert np.array_equal(np.sort(env.pos), np.arange(len(model.rest)))
    n = 3 * len(model.rest)
    assert env.values.size < 0.25 * n * (n + 1) / 2  # a quarter of the lower triangle or less
    assert np.all(env.first <= np.arange(n)) and np.all(env.first % 3 == 0)


def test_envelope_cholesky_and_sherman_morrison_match_a_dense_solve(system):
    model, ws, s, free, diagonal, rhs, exact = system
    env = envelope.build_envelope(len(model.rest), model.triangles, model.hinges)
    envelope.assemble(env, model.triangles, ws.tri_hess, model.hinges, ws.hinge_hess, diagonal, free)
    assert envelope.cholesky(env)
    out = np.zeros_like(rhs)
    envelope.solve_rank_one(env, free, s, ws.dvol, rhs, out, np.zeros_like(rhs))
    assert np.abs(out - exact).max() < 1e-12 * np.abs(exact).max()
    assert np.all(out[~free] == 0.0)


def test_cholesky_reports_a_matrix_that_is_not_positive_definite(system):
    model, ws, _, free, diagonal, _, _ = system
    env = envelope.build_envelope(len(model.rest), model.triangles, model.hinges)
    envelope.assemble(env, model.triangles, ws.tri_hess, model.hinges, ws.hinge_hess, -diagonal, free)
    assert not envelope.cholesky(env)


def operator(model, ws, s, diagonal):
    """The system's cg.Operator: the element matrices assembled, the diagonal and the gas term."""
    pattern = blocks.block_pattern(len(model.rest), model.triangles, model.hinges)
    op = cg.make_operator(pattern, 1)
    blocks.assemble(pattern, ws.tri_hess, ws.hinge_hess, 1.0, op.values)
    for c in range(3):
        op.vertex_blocks[:, c, c] = diagonal[:, c]
    op.vectors[0] = ws.dvol
    op.weights[0] = s
    return op


def test_the_block_sparse_operator_is_the_dense_matrix(system):
    model, ws, s, _, diagonal, rhs, _ = system
    dense = assemble_dense(model.triangles, ws.tri_hess, len(rhs)) + assemble_dense(
        model.hinges, ws.hinge_hess, len(rhs)
    )
    u = ws.dvol.reshape(-1)
    dense += s * np.outer(u, u) + np.diag(diagonal.reshape(-1))
    y = np.zeros_like(rhs)
    cg.apply(operator(model, ws, s, diagonal), rhs, y)
    expected = dense @ rhs.reshape(-1)
    assert np.abs(y.reshape(-1) - expected).max() < 1e-12 * np.abs(expected).max()


def test_jacobi_cg_matches_a_dense_solve(system):
    model, ws, s, free, diagonal, rhs, exact = system
    x = np.zeros_like(rhs)
    work = np.zeros((4,) + rhs.shape)
    op = operator(model, ws, s, diagonal)
    iterations = cg.pcg(op, free, rhs, x, work, 1e-12, 10_000)
    assert 0 < iterations < 10_000
    assert np.abs(x - exact).max() < 1e-9 * np.abs(exact).max()
    assert np.all(x[~free] == 0.0)
    assert cg.pcg(op, free, rhs, x, work, 1e-12, 3) == -1  # too few iterations: reported
