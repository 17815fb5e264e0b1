"""Conjugate gradients with a Jacobi (diagonal) preconditioner on a shell's linear systems: the
one CG of the package (the static systems of the benchmarks and tests, and each time step's Newton
system, stepsolve.py), on the operator it is handed.

The operator (N/m) is a block-sparse matrix (blocks.py) plus 3 x 3 vertex blocks plus low-rank
terms::

    A = B + blockdiag(D_v) + sum_k w_k u_k u_k^T

(``D`` (V, 3, 3): a diagonal mass term, the grounds' barriers and friction; ``u_k`` (K, V, 3)
with weights ``w_k``: the gas's rank-one term ``s dV dV^T``, the damping's rank-6 term
``-d W W^T``; a zero weight is skipped). :func:`pcg` solves ``A x = r`` over
the free degrees of freedom until ``|residual| <= rtol |r|`` (2-norms) or ``max_iter`` iterations;
fixed entries of ``x`` are zero.
"""

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ..physics.base.jit import kernel
from . import blocks


class Operator(NamedTuple):
    """``A`` of the module doc: its block matrix and the terms added to it."""

    pattern: blocks.BlockPattern
    values: NDArray[np.float64]  # (B, 3, 3) N/m
    vertex_blocks: NDArray[np.float64]  # (V, 3, 3) N/m
    vectors: NDArray[np.float64]  # (K, V, 3)
    weights: NDArray[np.float64]  # (K,)


def make_operator(pattern: blocks.BlockPattern, rank: int) -> Operator:
    """An operator of ``pattern`` with room for ``rank`` low-rank terms, all zero."""
    n_vertices = len(pattern.row_start) - 1
    z = np.zeros
    values = z((len(pattern.cols), 3, 3))
    return Operator(pattern, values, z((n_vertices, 3, 3)), z((rank, n_vertices, 3)), z(rank))


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
def matrix_diagonal(op, out):
    """The diagonal of ``A`` into ``out`` (V, 3)."""
    for v in range(out.shape[0]):
        k = op.pattern.diagonal_slot[v]
        for c in range(3):
            out[v, c] = op.values[k, c, c] + op.vertex_blocks[v, c, c]
            for j in range(op.weights.shape[0]):
                out[v, c] += op.weights[j] * op.vectors[j, v, c] * op.vectors[j, v, c]


@kernel
def _dot(a, b, free):
    s = 0.0
    for v in range(a.shape[0]):
        for c in range(3):
            if free[v, c]:
                s += a[v, c] * b[v, c]
    return s


@kernel
def pcg(op, free, rhs, x, work, rtol, max_iter):
    """Jacobi-preconditioned CG on ``A x = rhs`` from ``x = 0``; ``work`` (4, V, 3) scratch. Returns
    the iterations taken, or -1 if ``max_iter`` was reached first."""
    r, p, q, dinv = work[0], work[1], work[2], work[3]
    matrix_diagonal(op, dinv)
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
        apply(op, p, q)
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
