"""Conjugate gradients with a block-Jacobi preconditioner on a shell's linear systems: the one CG
of the package (the static systems of the benchmarks and tests, and each time step's Newton
system, stepsolve.py), on the operator it is handed.

The operator (N/m) is a block-sparse matrix (blocks.py) plus 3 x 3 vertex blocks plus low-rank
terms::

    A = B + blockdiag(D_v) + sum_k w_k u_k u_k^T

(``D`` (V, 3, 3): a diagonal mass term, the grounds' barriers and friction; ``u_k`` (K, V, 3)
with weights ``w_k``: the gas's rank-one term ``s dV dV^T``, the damping's rank-6 term
``-d W W^T``; a zero weight is skipped). :func:`pcg` solves ``A x = r`` over the free degrees of
freedom until ``|residual| <= rtol |r|`` (2-norms) or ``max_iter`` iterations; fixed entries of
``x`` are zero. The preconditioner is the inverse of each vertex's 3 x 3
diagonal block of ``A`` (the blocks' off-diagonal terms carry the skin's in-plane stiffness and a
ground's normal, which a diagonal alone misses).
"""

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ...physics.base.jit import kernel
from . import blocks


class Operator(NamedTuple):
    """``A`` of the module doc: its block matrix and the terms added to it."""

    pattern: blocks.BlockPattern
    values: NDArray[np.float64]  # (B, 3, 3) N/m
    vertex_blocks: NDArray[np.float64]  # (V, 3, 3) N/m
    vectors: NDArray[np.float64]  # (K, V, 3)
    weights: NDArray[np.float64]  # (K,)
    inverses: NDArray[np.float64]  # (V, 3, 3) 1/(N/m): the preconditioner (block_inverses)
    hinge_values: NDArray[np.float64]  # (B, 3, 3) N/m: the hinges' part of ``values``, unscaled


def make_operator(pattern: blocks.BlockPattern, rank: int) -> Operator:
    """An operator of ``pattern`` with room for ``rank`` low-rank terms, all zero."""
    n_vertices = len(pattern.row_start) - 1
    z = np.zeros
    values = z((len(pattern.cols), 3, 3))
    blocks3 = (n_vertices, 3, 3)
    vectors = z((rank, n_vertices, 3))
    return Operator(pattern, values, z(blocks3), vectors, z(rank), z(blocks3), z(values.shape))


@kernel
def apply(op, x, y):
    """``y = A x`` (V, 3)."""
    blocks.multiply(op.pattern, op.values, x, y)
    d = op.vertex_blocks
    for v in range(x.shape[0]):
        x0, x1, x2 = x[v, 0], x[v, 1], x[v, 2]
        for c in range(3):
            y[v, c] += d[v, c, 0] * x0 + d[v, c, 1] * x1 + d[v, c, 2] * x2
    for k in range(op.weights.shape[0]):
        if op.weights[k] == 0.0:
            continue
        ux = 0.0
        for v in range(x.shape[0]):
            for c in range(3):
                ux += op.vectors[k, v, c] * x[v, c]
        f = op.weights[k] * ux
        for v in range(x.shape[0]):
            for c in range(3):
                y[v, c] += f * op.vectors[k, v, c]


@kernel
def _vertex_block(op, v, out):
    """The diagonal 3 x 3 block of vertex ``v`` of ``A`` into ``out`` (3, 3)."""
    k = op.pattern.diagonal_slot[v]
    for a in range(3):
        for b in range(3):
            out[a, b] = op.values[k, a, b] + op.vertex_blocks[v, a, b]
            for j in range(op.weights.shape[0]):
                out[a, b] += op.weights[j] * op.vectors[j, v, a] * op.vectors[j, v, b]


@kernel
def block_inverses(op, free, out):
    """The block-Jacobi preconditioner into ``out`` (V, 3, 3): the inverse of each vertex's diagonal
    block of ``A`` (by cofactors), or, for a vertex with a fixed component or a block that is not
    positive definite, the inverse of its diagonal on the free components (zero on the fixed)."""
    for v in range(out.shape[0]):
        m = out[v]
        _vertex_block(op, v, m)
        c00 = m[1, 1] * m[2, 2] - m[1, 2] * m[2, 1]
        c01 = m[1, 2] * m[2, 0] - m[1, 0] * m[2, 2]
        c02 = m[1, 0] * m[2, 1] - m[1, 1] * m[2, 0]
        det = m[0, 0] * c00 + m[0, 1] * c01 + m[0, 2] * c02
        minor = m[0, 0] * m[1, 1] - m[0, 1] * m[1, 0]
        if free[v, 0] and free[v, 1] and free[v, 2] and m[0, 0] > 0.0 and minor > 0.0 and det > 0.0:
            c11 = m[0, 0] * m[2, 2] - m[0, 2] * m[2, 0]
            c12 = m[0, 1] * m[2, 0] - m[0, 0] * m[2, 1]
            c22 = minor
            m[0, 0], m[0, 1], m[0, 2] = c00 / det, c01 / det, c02 / det
            m[1, 0], m[1, 1], m[1, 2] = c01 / det, c11 / det, c12 / det
            m[2, 0], m[2, 1], m[2, 2] = c02 / det, c12 / det, c22 / det
            continue
        for a in range(3):
            d = m[a, a]
            for b in range(3):
                m[a, b] = 0.0
            m[a, a] = 1.0 / d if free[v, a] else 0.0


@kernel
def _dot(a, b, free):
    s = 0.0
    for v in range(a.shape[0]):
        for c in range(3):
            if free[v, c]:
                s += a[v, c] * b[v, c]
    return s


@kernel
def _precondition(inverses, r, z):
    """``z = P r`` with the block inverses (V, 3, 3); returns ``r . z``."""
    rz = 0.0
    for v in range(r.shape[0]):
        r0, r1, r2 = r[v, 0], r[v, 1], r[v, 2]
        for c in range(3):
            z[v, c] = inverses[v, c, 0] * r0 + inverses[v, c, 1] * r1 + inverses[v, c, 2] * r2
            rz += r[v, c] * z[v, c]
    return rz


@kernel
def pcg(op, free, rhs, x, work, rtol, max_iter):
    """Block-Jacobi-preconditioned CG on ``A x = rhs`` from ``x = 0``; ``work`` (4, V, 3) scratch.
    Returns the iterations taken, or -1 if ``max_iter`` was reached first."""
    r, p, q, z = work[0], work[1], work[2], work[3]
    block_inverses(op, free, op.inverses)
    for v in range(x.shape[0]):
        for c in range(3):
            x[v, c] = 0.0
            r[v, c] = rhs[v, c] if free[v, c] else 0.0
    rz = _precondition(op.inverses, r, p)
    goal = rtol * np.sqrt(_dot(r, r, free))
    for it in range(max_iter):
        if np.sqrt(_dot(r, r, free)) <= goal:
            return it
        apply(op, p, q)
        alpha = rz / _dot(p, q, free)
        for v in range(x.shape[0]):
            for c in range(3):
                x[v, c] += alpha * p[v, c]
                r[v, c] -= alpha * q[v, c]
        rz_new = _precondition(op.inverses, r, z)
        beta = rz_new / rz
        rz = rz_new
        for v in range(x.shape[0]):
            for c in range(3):
                p[v, c] = z[v, c] + beta * p[v, c]
    return -1
