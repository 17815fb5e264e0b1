"""The nearest positive semi-definite matrix to a small symmetric one (Frobenius norm).

A contact pair's barrier Hessian (contact.py) is indefinite where the distance's own curvature
enters with the barrier's negative slope; Newton's matrix must stay positive definite for CG, so,
as Incremental Potential Contact does, each pair's matrix ``H = Q diag(lambda) Q^T`` is replaced by
``Q diag(max(lambda, 0)) Q^T``. The eigenvalues come from cyclic Jacobi rotations (Golub & Van
Loan, 8.5) until the off-diagonal part is ``JACOBI_TOL`` of the matrix's norm (entries below
``JACOBI_TOL / n`` of it are set to zero instead of rotated), in place, without allocating.
"""

import math

from ...physics.base.jit import kernel

JACOBI_TOL = 1e-13  # relative off-diagonal size at which the rotations stop
JACOBI_SWEEPS = 30  # at most this many sweeps (converges quadratically: 6 to 10 in practice)


@kernel
def _off_diagonal(a):
    """``(sum of squared off-diagonal entries, squared Frobenius norm)``."""
    off = total = 0.0
    n = a.shape[0]
    for p in range(n):
        for q in range(n):
            total += a[p, q] * a[p, q]
            if p != q:
                off += a[p, q] * a[p, q]
    return off, total


@kernel
def _rotate(a, v, p, q):
    """One Jacobi rotation zeroing ``a[p, q]``, accumulated into ``v``."""
    apq = a[p, q]
    tau = (a[q, q] - a[p, p]) / (2.0 * apq)
    t = (1.0 if tau >= 0.0 else -1.0) / (abs(tau) + math.sqrt(1.0 + tau * tau))
    c = 1.0 / math.sqrt(1.0 + t * t)
    s = t * c
    n = a.shape[0]
    for k in range(n):
        akp, akq = a[k, p], a[k, q]
        a[k, p], a[k, q] = c * akp - s * akq, s * akp + c * akq
    for k in range(n):
        apk, aqk = a[p, k], a[q, k]
        a[p, k], a[q, k] = c * apk - s * aqk, s * apk + c * aqk
    for k in range(n):
        vkp, vkq = v[k, p], v[k, q]
        v[k, p], v[k, q] = c * vkp - s * vkq, s * vkp + c * vkq


@kernel
def project_psd(a, v, lam):
    """Replaces the symmetric ``a`` (n, n) by its nearest positive semi-definite matrix; ``v``
    (n, n) and ``lam`` (n,) scratch (eigenvectors and eigenvalues). Returns the most negative
    eigenvalue (0 if none)."""
    n = a.shape[0]
    for p in range(n):
        for q in range(n):
            v[p, q] = 1.0 if p == q else 0.0
    for _ in range(JACOBI_SWEEPS):
        off, total = _off_diagonal(a)
        if off <= JACOBI_TOL * JACOBI_TOL * total:
            break
        small = JACOBI_TOL * math.sqrt(total) / n
        for p in range(n - 1):
            for q in range(p + 1, n):
                if abs(a[p, q]) > small:
                    _rotate(a, v, p, q)
                else:
                    a[p, q] = a[q, p] = 0.0  # below the tolerance: no rotation (nor subnormal numbers)
    lowest = 0.0
    for k in range(n):
        lowest = min(lowest, a[k, k])
        lam[k] = max(a[k, k], 0.0)
    for p in range(n):
        for q in range(p, n):
            s = 0.0
            for k in range(n):
                s += v[p, k] * lam[k] * v[q, k]
            a[p, q] = a[q, p] = s
    return lowest


@kernel
def project_psd_in(a, basis, small, vecs, lam):
    """:func:`project_psd` of a symmetric ``a`` (n, n) whose range lies in the span of the rows of
    ``basis`` (k, n), orthonormal or zero: ``a = B^T S B`` with ``S = B a B^T`` (k, k), so the
    projection is ``B^T S_+ B`` (eigenvalues of a k x k matrix instead of an n x n one). ``small``,
    ``vecs`` (k, k) and ``lam`` (k,) scratch. Returns the most negative eigenvalue (0 if none)."""
    k, n = basis.shape
    for i in range(k):
        for j in range(i, k):
            s = 0.0
            for p in range(n):
                if basis[i, p] == 0.0:
                    continue
                t = 0.0
                for q in range(n):
                    t += a[p, q] * basis[j, q]
                s += basis[i, p] * t
            small[i, j] = small[j, i] = s
    lowest = project_psd(small, vecs, lam)
    for p in range(n):
        for q in range(p, n):
            s = 0.0
            for i in range(k):
                for j in range(k):
                    s += basis[i, p] * small[i, j] * basis[j, q]
            a[p, q] = a[q, p] = s
    return lowest
