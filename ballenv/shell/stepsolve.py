"""The linear solve of a time step's Newton iteration, chosen by measurement
(``benchmarks/results/shell_linear_solve.md``: with the mass term ``M / h^2`` CG is 11-27 times
faster than the envelope factorisation at ``h = 1e-4 s``).

The matrix (N/m) is ``A = sum_e K_e + blocks + diag(D) + s u u^T - d W^T W``: element matrices
(triangles, hinges), 3 x 3 vertex blocks (grounds' barriers, friction), a diagonal (the mass term),
the gas's rank-one term (``s`` Pa/m^3, ``u = dV/dx``) and the damping's rank-6 term (``d`` 1/s^2
times ``W`` of damping.py); every degree of freedom is free (a step fixes none). The vertex blocks
are added to the diagonal block of one triangle of each vertex (exact). Jacobi-preconditioned CG
applies it element by element (:func:`pcg`) to a residual of ``CG_RTOL`` of the right-hand side
(an inexact Newton direction: Newton's own test on the gradient sets the accuracy); if it does
not get there within ``CG_MAX_ITER`` iterations, the envelope Cholesky with
Sherman-Morrison solves the matrix without the rank-6 term (still symmetric positive definite, so
Newton's direction stays one of descent).
"""

import numpy as np
from numpy.typing import NDArray

from ..physics.base.jit import kernel
from . import envelope
from .cg import _dot, matrix_diagonal

CG_RTOL = 1e-5
CG_MAX_ITER = 400


def block_owners(
    triangles: NDArray[np.int64], n_vertices: int
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """For each vertex, a triangle holding it and its corner there: ``(triangle (V,), corner (V,))``."""
    tri = np.full(n_vertices, -1, dtype=np.int64)
    corner = np.zeros(n_vertices, dtype=np.int64)
    for c in range(3):
        unset = tri[triangles[:, c]] < 0
        tri[triangles[unset, c]] = np.nonzero(unset)[0]
        corner[triangles[unset, c]] = c
    return tri, corner


@kernel
def fold_blocks(tri_mats, owner_tri, owner_corner, blocks):
    """Adds each vertex's block (V, 3, 3) to its owning triangle's diagonal block."""
    for v in range(blocks.shape[0]):
        t, c = owner_tri[v], 3 * owner_corner[v]
        for a in range(3):
            for b in range(3):
                tri_mats[t, c + a, c + b] += blocks[v, a, b]


@kernel(fastmath=True)
def _apply_elements(elements, mats, x, y, local):
    """``y += sum_e K_e x_e`` with every degree of freedom free; ``local`` (12,) scratch."""
    n = 3 * elements.shape[1]
    for e in range(elements.shape[0]):
        for i in range(n):
            local[i] = x[elements[e, i // 3], i % 3]
        for i in range(n):
            s = 0.0
            for j in range(n):
                s += mats[e, i, j] * local[j]
            y[elements[e, i // 3], i % 3] += s


@kernel
def _apply(triangles, tri_mats, hinges, hinge_mats, diagonal, s, u, d, w, x, y, local):
    """``y = A x`` (module doc) with every degree of freedom free."""
    ux = 0.0
    for v in range(x.shape[0]):
        for c in range(3):
            y[v, c] = diagonal[v, c] * x[v, c]
            ux += u[v, c] * x[v, c]
    _apply_elements(triangles, tri_mats, x, y, local)
    _apply_elements(hinges, hinge_mats, x, y, local)
    for v in range(x.shape[0]):
        for c in range(3):
            y[v, c] += s * ux * u[v, c]
    for k in range(w.shape[0]):
        wx = 0.0
        for v in range(x.shape[0]):
            for c in range(3):
                wx += w[k, v, c] * x[v, c]
        for v in range(x.shape[0]):
            for c in range(3):
                y[v, c] -= d * wx * w[k, v, c]


@kernel
def pcg(
    triangles, tri_mats, hinges, hinge_mats, diagonal, s, u, d, w, free, rhs, x, work, local, rtol, max_iter
):
    """Jacobi-preconditioned CG on ``A x = rhs`` (module doc) from ``x = 0``, every degree of
    freedom free; ``work`` (4, V, 3) and ``local`` (12,) scratch. Returns the iterations taken, or
    -1 if ``max_iter`` was reached first."""
    r, p, q, dinv = work[0], work[1], work[2], work[3]
    matrix_diagonal(triangles, tri_mats, hinges, hinge_mats, diagonal, s, u, dinv)
    for k in range(w.shape[0]):
        for v in range(x.shape[0]):
            for c in range(3):
                dinv[v, c] -= d * w[k, v, c] * w[k, v, c]
    for v in range(x.shape[0]):
        for c in range(3):
            dinv[v, c] = 1.0 / dinv[v, c] if free[v, c] else 0.0
            x[v, c] = 0.0
            r[v, c] = rhs[v, c] if free[v, c] else 0.0
            p[v, c] = dinv[v, c] * r[v, c]
    goal = rtol * np.sqrt(_dot(r, r, free))
    rz = _dot(r, p, free)
    for it in range(max_iter):
        if np.sqrt(_dot(r, r, free)) <= goal:
            return it
        _apply(triangles, tri_mats, hinges, hinge_mats, diagonal, s, u, d, w, p, q, local)
        alpha = rz / _dot(p, q, free)
        rz_new = 0.0
        for v in range(x.shape[0]):
            for c in range(3):
                x[v, c] += alpha * p[v, c]
                r[v, c] -= alpha * q[v, c]
                rz_new += r[v, c] * dinv[v, c] * r[v, c]
        beta = rz_new / rz
        rz = rz_new
        for v in range(x.shape[0]):
            for c in range(3):
                p[v, c] = dinv[v, c] * r[v, c] + beta * p[v, c]
    return -1


def solve(problem, s, diagonal, d, w, rhs, work):
    """``A^-1 rhs`` (module doc) for ``problem`` (equilibrium.Problem) whose workspace holds the
    element matrices with the vertex blocks folded in; ``(solution, CG iterations or -1 when the
    envelope solved it)``."""
    m, ws, free = problem.model, problem.ws, problem.free
    out = np.zeros_like(rhs)
    args = (
        m.triangles,
        ws.tri_hess,
        m.hinges,
        ws.hinge_hess,
        diagonal,
        s,
        ws.dvol,
        d,
        w,
        free,
        rhs,
        out,
        work,
    )
    iterations = pcg(*args, np.zeros(12), CG_RTOL, CG_MAX_ITER)
    if iterations >= 0:
        return out, iterations
    envelope.assemble(problem.env, m.triangles, ws.tri_hess, m.hinges, ws.hinge_hess, diagonal, free)
    if not envelope.cholesky(problem.env):
        raise np.linalg.LinAlgError("the step's matrix is not positive definite")
    envelope.solve_rank_one(problem.env, free, s, ws.dvol, rhs, out, np.zeros_like(rhs))
    return out, -1
