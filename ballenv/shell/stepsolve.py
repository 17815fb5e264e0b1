"""The linear solve of a time step's Newton iteration, chosen by measurement
(``benchmarks/results/shell_linear_solve.md``: with the mass term ``M / h^2`` CG is 11-27 times
faster than the envelope factorisation at ``h = 1e-4 s``).

The matrix (N/m) is ``A = c_x sum_e K_e + blocks + diag(D) + s u u^T - d W^T W``: element matrices
(triangles, hinges, scaled by ``c_x``), 3 x 3 vertex blocks (grounds' barriers, friction), a
diagonal (the mass term), the gas's rank-one term (``s`` Pa/m^3, ``u = dV/dx``) and the damping's
rank-6 term (``d`` 1/s^2 times ``W`` of damping.py); every degree of freedom is free (a step fixes
none). It is assembled as a block-sparse matrix (blocks.py) and solved by Jacobi-preconditioned CG
(cg.py) to a residual of ``CG_RTOL`` of the right-hand side (an inexact Newton direction: Newton's
own test on the gradient sets the accuracy); if CG does not get there within ``CG_MAX_ITER``
iterations, the envelope Cholesky with Sherman-Morrison solves the matrix without the rank-6 term
(still symmetric positive definite, so Newton's direction stays one of descent).
"""

import numpy as np
from numpy.typing import NDArray

from ..physics.base.jit import kernel
from . import blocks, cg, envelope

CG_RTOL = 1e-5
CG_MAX_ITER = 400
RANK = 7  # the operator's low-rank terms: the gas's and the damping's six


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


@kernel
def _scale(mats, factor):
    m = mats.reshape(mats.size)
    for k in range(m.size):
        m[k] *= factor


@kernel
def _envelope_solve(problem, owners, c_x, s, vertex_blocks, diagonal, rhs, out, z):
    """The fallback (module doc): True if the matrix without the damping term was factorised."""
    m, ws, free = problem.model, problem.ws, problem.free
    _scale(ws.tri_hess, c_x)
    _scale(ws.hinge_hess, c_x)
    fold_blocks(ws.tri_hess, owners[0], owners[1], vertex_blocks)
    envelope.assemble(problem.env, m.triangles, ws.tri_hess, m.hinges, ws.hinge_hess, diagonal, free)
    if not envelope.cholesky(problem.env):
        return False
    envelope.solve_rank_one(problem.env, free, s, ws.dvol, rhs, out, z)
    return True


@kernel
def solve(problem, owners, op, c_x, s, vertex_blocks, mass_term, d, basis, rhs, out, work):
    """``out = A^-1 rhs`` (module doc) with the element matrices (unscaled) and ``dV/dx`` in the
    workspace of ``problem`` (equilibrium.Problem), the vertex blocks (V, 3, 3), the diagonal
    ``mass_term`` (V,) per vertex and the rank-6 ``basis`` (6, V, 3) or (0, V, 3). Returns the CG
    iterations, -1 when the envelope solved it, -2 when that matrix was not positive definite."""
    ws = problem.ws
    blocks.assemble(op.pattern, ws.tri_hess, ws.hinge_hess, c_x, vertex_blocks, op.values)
    for v in range(rhs.shape[0]):
        for c in range(3):
            op.diagonal[v, c] = mass_term[v]
            op.vectors[0, v, c] = ws.dvol[v, c]
    op.weights[:] = 0.0
    op.weights[0] = s
    for k in range(basis.shape[0]):
        op.weights[1 + k] = -d
        for v in range(rhs.shape[0]):
            for c in range(3):
                op.vectors[1 + k, v, c] = basis[k, v, c]
    iterations = cg.pcg(op, problem.free, rhs, out, work, CG_RTOL, CG_MAX_ITER)
    if iterations >= 0:
        return iterations
    if _envelope_solve(problem, owners, c_x, s, vertex_blocks, op.diagonal, rhs, out, work[0]):
        return -1
    return -2
