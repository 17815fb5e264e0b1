"""The linear solve of a time step's Newton iteration, chosen by measurement
(``benchmarks/results/shell_linear_solve.md``: with the mass term ``M / h^2`` CG against the
envelope factorisation).

The matrix (N/m) is ``A = c_x sum_e K_e + blocks + diag(D) + s u u^T - d W^T W``: element matrices
(triangles, hinges, scaled by ``c_x``; they may be an earlier iterate's, see implicit.py), 3 x 3
vertex blocks (grounds' barriers, friction), a diagonal (the mass term), the gas's rank-one term
(``s`` Pa/m^3, ``u = dV/dx``) and the damping's rank-6 term (``d`` 1/s^2 times ``W`` of
damping.py); every degree of freedom is free (a step fixes none). It is a block-sparse matrix
(blocks.py) with the vertex blocks and low-rank terms apart (cg.Operator), solved by
block-Jacobi-preconditioned CG (cg.py) to a residual of ``rtol`` of the right-hand side, set by the
Newton iteration (an inexact Newton direction: Newton's own test on the gradient sets the
accuracy); if CG does not get there within ``CG_MAX_ITER`` iterations, the envelope Cholesky with
Sherman-Morrison solves the matrix without the rank-6 term (still symmetric positive definite, so
Newton's direction stays one of descent).
"""

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ...physics.base.jit import kernel
from . import blocks, cg, envelope

CG_MAX_ITER = 400
RANK = 7  # the operator's low-rank terms: the gas's and the damping's six


class Owners(NamedTuple):
    """For each vertex, a triangle holding it and its corner there."""

    triangle: NDArray[np.int64]  # (V,)
    corner: NDArray[np.int64]  # (V,)


def block_owners(triangles: NDArray[np.int64], n_vertices: int) -> Owners:
    """Each vertex's owning triangle and corner (:class:`Owners`)."""
    tri = np.full(n_vertices, -1, dtype=np.int64)
    corner = np.zeros(n_vertices, dtype=np.int64)
    for c in range(3):
        unset = tri[triangles[:, c]] < 0
        tri[triangles[unset, c]] = np.nonzero(unset)[0]
        corner[triangles[unset, c]] = c
    return Owners(tri, corner)


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
def _envelope_solve(problem, owners, c_x, s, vertex_blocks, rhs, out, z, zero):
    """The fallback (module doc): True if the matrix without the damping term was factorised. The
    workspace's element matrices are left scaled, with the vertex blocks folded in."""
    m, ws, free = problem.model, problem.ws, problem.free
    _scale(ws.tri_hess, c_x)
    _scale(ws.hinge_hess, c_x)
    fold_blocks(ws.tri_hess, owners.triangle, owners.corner, vertex_blocks)
    zero[:] = 0.0
    envelope.assemble(problem.env, m.triangles, ws.tri_hess, m.hinges, ws.hinge_hess, zero, free)
    if not envelope.cholesky(problem.env):
        return False
    envelope.solve_rank_one(problem.env, free, s, ws.dvol, rhs, out, z)
    return True


@kernel
def load(problem, op, coefficients, contact_blocks, mass_term, basis, assemble):
    """``A`` (module doc) into ``op``, with the triangles' matrices (unscaled) and ``dV/dx`` in the
    workspace of ``problem`` (equilibrium.Problem) and the hinges' part in ``op.hinge_values``
    (blocks.assemble_hinges), assembled if ``assemble`` (else those assembled before),
    ``coefficients = (c_x, s, d, CG's rtol)``, the contact's vertex blocks (V, 3, 3), the diagonal
    ``mass_term`` (V,) per vertex and the rank-6 ``basis`` (6, V, 3) or (0, V, 3)."""
    ws = problem.ws
    c_x, s, d, _ = coefficients
    if assemble:
        blocks.assemble_kept(op.pattern, ws.tri_hess, op.hinge_values, c_x, op.values)
    for v in range(mass_term.shape[0]):
        for a in range(3):
            for b in range(3):
                op.vertex_blocks[v, a, b] = contact_blocks[v, a, b] + (mass_term[v] if a == b else 0.0)
            op.vectors[0, v, a] = ws.dvol[v, a]
    op.weights[:] = 0.0
    op.weights[0] = s
    for k in range(basis.shape[0]):
        op.weights[1 + k] = -d
        for v in range(mass_term.shape[0]):
            for c in range(3):
                op.vectors[1 + k, v, c] = basis[k, v, c]


@kernel
def solve(problem, owners, op, coefficients, contact_blocks, mass_term, basis, rhs, out, work, assemble):
    """``out = A^-1 rhs`` (module doc), ``A`` loaded into ``op`` (:func:`load`, the same arguments).
    Returns the CG iterations, -1 when the envelope solved it (the workspace's element matrices are
    then changed), -2 when that matrix was not positive definite."""
    c_x, s, _, rtol = coefficients
    load(problem, op, coefficients, contact_blocks, mass_term, basis, assemble)
    iterations = cg.pcg(op, problem.free, rhs, out, work, rtol, CG_MAX_ITER)
    if iterations >= 0:
        return iterations
    if _envelope_solve(problem, owners, c_x, s, op.vertex_blocks, rhs, out, work[0], work[1]):
        return -1
    return -2
