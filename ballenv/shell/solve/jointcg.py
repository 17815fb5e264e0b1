"""Block-Jacobi-preconditioned CG on the Newton system of a joint step (joint.py): the shells'
operators (cg.Operator, loaded by stepsolve.load) on the diagonal, coupled by the touching contact
pairs' projected barrier Hessians (contact.py)::

    A = blockdiag(A_1, ..., A_S) + sum_pairs P_pair^T H_pair P_pair

(N/m; ``P_pair`` picks the pair's four vertices out of the stacked unknowns (S, V, 3)). Each pair's
diagonal 3 x 3 blocks are already in its vertices' blocks of ``A_k`` (so in the preconditioner,
each vertex's 3 x 3 diagonal block inverted, as in cg.py); :func:`apply` adds the off-diagonal
ones. Each shell's gas (rank one) and damping (rank 6) terms stay in its own operator. The iteration
is cg.py's, over the stacked unknowns, to ``|residual| <= rtol |rhs|``.
"""

from ...physics.base.jit import copy_into, kernel
from . import cg


@kernel
def apply(sts, jt, x, y):
    """``y = A x`` (S, V, 3) (module doc)."""
    for k in range(x.shape[0]):
        cg.apply(sts[k].op, x[k], y[k])
    n = x.shape[0] * x.shape[1]
    xf, yf = x.reshape((n, 3)), y.reshape((n, 3))
    for a in range(jt.n_active[0]):
        idx, h = jt.active[a], jt.hess[a]
        for m in range(4):
            for q in range(4):
                if m == q:
                    continue
                for r in range(3):
                    s = 0.0
                    for c in range(3):
                        s += h[3 * m + r, 3 * q + c] * xf[idx[q], c]
                    yf[idx[m], r] += s


@kernel
def _dot(a, b):
    s = 0.0
    for k in range(a.shape[0]):
        for v in range(a.shape[1]):
            for c in range(3):
                s += a[k, v, c] * b[k, v, c]
    return s


@kernel
def _precondition(sts, r, z):
    """``z = P r`` with each shell's block inverses; returns ``r . z``."""
    rz = 0.0
    for k in range(r.shape[0]):
        inverses = sts[k].op.inverses
        for v in range(r.shape[1]):
            r0, r1, r2 = r[k, v, 0], r[k, v, 1], r[k, v, 2]
            for c in range(3):
                z[k, v, c] = inverses[v, c, 0] * r0 + inverses[v, c, 1] * r1 + inverses[v, c, 2] * r2
                rz += r[k, v, c] * z[k, v, c]
    return rz


@kernel
def pcg(sts, jt, rhs, x, rtol, max_iter):
    """CG on ``A x = rhs`` (S, V, 3) from ``x = 0`` with ``jt.cg`` as scratch. Returns the
    iterations taken, or -1 if ``max_iter`` was reached first."""
    r, p, q, z = jt.cg[0], jt.cg[1], jt.cg[2], jt.cg[3]
    for k in range(x.shape[0]):
        cg.block_inverses(sts[k].op, sts[k].problem.free, sts[k].op.inverses)
    x[:] = 0.0
    copy_into(r, rhs)
    rz = _precondition(sts, r, p)
    goal = rtol * _dot(r, r) ** 0.5
    for it in range(max_iter):
        if _dot(r, r) ** 0.5 <= goal:
            return it
        apply(sts, jt, p, q)
        alpha = rz / _dot(p, q)
        for k in range(x.shape[0]):
            for v in range(x.shape[1]):
                for c in range(3):
                    x[k, v, c] += alpha * p[k, v, c]
                    r[k, v, c] -= alpha * q[k, v, c]
        rz_new = _precondition(sts, r, z)
        beta = rz_new / rz
        rz = rz_new
        for k in range(x.shape[0]):
            for v in range(x.shape[1]):
                for c in range(3):
                    p[k, v, c] = z[k, v, c] + beta * p[k, v, c]
    return -1
