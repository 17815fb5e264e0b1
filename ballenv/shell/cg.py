"""Conjugate gradients with a Jacobi (diagonal) preconditioner on a shell's Newton system, the
matrix applied element by element (its triangles' and hinges' matrices, the rank-one gas term and a
diagonal), never assembled: the iterative alternative to the envelope Cholesky (envelope.py).

Solves ``(K + diag(D) + s u u^T) x = r`` over the free degrees of freedom until
``|residual| <= rtol |r|`` (2-norms) or ``max_iter`` iterations; fixed entries of ``x`` are zero.
"""

import numpy as np

from ..physics.base.jit import kernel


@kernel
def _apply_elements(elements, mats, x, free, y):
    n_v = elements.shape[1]
    for e in range(elements.shape[0]):
        for a in range(n_v):
            for c in range(3):
                va = elements[e, a]
                if not free[va, c]:
                    continue
                s = 0.0
                for b in range(n_v):
                    vb = elements[e, b]
                    for d in range(3):
                        s += mats[e, 3 * a + c, 3 * b + d] * x[vb, d]
                y[va, c] += s


@kernel
def apply(triangles, tri_mats, hinges, hinge_mats, diagonal, s, u, free, x, y):
    """``y`` = (K + diag + s u u^T) ``x`` on the free entries (``x`` zero on the fixed ones)."""
    ux = 0.0
    for v in range(x.shape[0]):
        for c in range(3):
            y[v, c] = diagonal[v, c] * x[v, c]
            ux += u[v, c] * x[v, c]
    _apply_elements(triangles, tri_mats, x, free, y)
    _apply_elements(hinges, hinge_mats, x, free, y)
    for v in range(x.shape[0]):
        for c in range(3):
            y[v, c] = y[v, c] + s * ux * u[v, c] if free[v, c] else 0.0


@kernel
def matrix_diagonal(triangles, tri_mats, hinges, hinge_mats, diagonal, s, u, out):
    """The diagonal of (K + diag + s u u^T) into ``out`` (V, 3)."""
    for v in range(out.shape[0]):
        for c in range(3):
            out[v, c] = diagonal[v, c] + s * u[v, c] * u[v, c]
    for e in range(triangles.shape[0]):
        for a in range(3):
            for c in range(3):
                out[triangles[e, a], c] += tri_mats[e, 3 * a + c, 3 * a + c]
    for e in range(hinges.shape[0]):
        for a in range(4):
            for c in range(3):
                out[hinges[e, a], c] += hinge_mats[e, 3 * a + c, 3 * a + c]


@kernel
def _dot(a, b, free):
    s = 0.0
    for v in range(a.shape[0]):
        for c in range(3):
            if free[v, c]:
                s += a[v, c] * b[v, c]
    return s


@kernel
def pcg(triangles, tri_mats, hinges, hinge_mats, diagonal, s, u, free, rhs, x, work, rtol, max_iter):
    """Jacobi-preconditioned CG from ``x = 0``; ``work`` (4, V, 3) scratch. Returns the iterations
    taken, or -1 if ``max_iter`` was reached first."""
    r, p, q, dinv = work[0], work[1], work[2], work[3]
    matrix_diagonal(triangles, tri_mats, hinges, hinge_mats, diagonal, s, u, dinv)
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
        apply(triangles, tri_mats, hinges, hinge_mats, diagonal, s, u, free, p, q)
        alpha = rz / _dot(p, q, free)
        for v in range(x.shape[0]):
            for c in range(3):
                x[v, c] += alpha * p[v, c]
                r[v, c] -= alpha * q[v, c]
        rz_new = 0.0
        for v in range(x.shape[0]):
            for c in range(3):
                rz_new += r[v, c] * dinv[v, c] * r[v, c]
        beta = rz_new / rz
        rz = rz_new
        for v in range(x.shape[0]):
            for c in range(3):
                p[v, c] = dinv[v, c] * r[v, c] + beta * p[v, c]
    return -1
