"""O(N) linear solve of a ring's Newton system.

The Jacobian of a ring with ``N`` nodes is a ``2N x 2N`` matrix whose node blocks (2x2) couple a node
with its two neighbours on each side *cyclically* (stretching couples i, i+1; bending couples i-1,
i, i+1). Renumbering the nodes in the zig-zag order ``0, N-1, 1, N-2, 2, ...`` puts every ring
neighbour within four positions, so the cyclic band becomes a plain band of half-width
``BAND_HALF_WIDTH = 2 * 4 + 1 = 9`` degrees of freedom. The band is factorised by LU without
pivoting (the matrix is dominated by the positive mass term ``M / (beta dt^2)``; a vanishing pivot is
reported and the step is rejected).

The dense but low-rank terms (the pressure's ``dp/dA`` term, rank 1; the damping's coupling to the
rigid-body motion, rank 3) are kept exactly with the Woodbury identity::

    (B + U V^T)^-1 r = y - Z (I + V^T Z)^-1 V^T y,   y = B^-1 r,  Z = B^-1 U.

Band storage: ``band[row, BAND_HALF_WIDTH + col - row] = A[row, col]`` in zig-zag DOF order; vectors
passed to the solver are in natural DOF order (``2 * node + component``).
"""

import numpy as np

from .jit import kernel

BAND_HALF_WIDTH = 9
BAND_COLUMNS = 2 * BAND_HALF_WIDTH + 1
MAX_LOW_RANK = 4
SOLVE_COLUMNS = 1 + MAX_LOW_RANK  # the right-hand side and the low-rank columns, solved together


def zigzag_positions(n_nodes):
    """Position of each node in the zig-zag order 0, N-1, 1, N-2, ... -> int64 array (N,)."""
    order = np.empty(n_nodes, dtype=np.int64)
    lo, hi = 0, n_nodes - 1
    for k in range(n_nodes):
        if k % 2 == 0:
            order[k] = lo
            lo += 1
        else:
            order[k] = hi
            hi -= 1
    pos = np.empty(n_nodes, dtype=np.int64)
    pos[order] = np.arange(n_nodes)
    return pos


@kernel
def band_add_block(band, pos, i, j, a00, a01, a10, a11):
    """Add the 2x2 block [[a00, a01], [a10, a11]] at node row ``i``, node column ``j``."""
    r = 2 * pos[i]
    c = 2 * pos[j]
    w = BAND_HALF_WIDTH
    band[r, w + c - r] += a00
    band[r, w + c + 1 - r] += a01
    band[r + 1, w + c - r - 1] += a10
    band[r + 1, w + c - r] += a11


@kernel(fastmath=True)
def band_lu(band):
    """Factorise a band matrix in place (LU, no pivoting). Returns False on a zero/non-finite pivot.

    Rows more than ``BAND_HALF_WIDTH`` from the end are eliminated with loops of the constant band
    width (unrolled and vectorised by the compiler; the operations and their order are those of the
    general loop of the last rows)."""
    n = band.shape[0]
    w = BAND_HALF_WIDTH
    for k in range(n):
        row_k = band[k]
        pivot = row_k[w]
        if not (abs(pivot) > 1e-300) or not np.isfinite(pivot):
            return False
        inv = 1.0 / pivot
        if k + w < n:
            for i in range(1, w + 1):
                _eliminate(band[k + i], row_k, w - i, inv, w)
        else:
            for i in range(1, n - k):
                _eliminate(band[k + i], row_k, w - i, inv, n - 1 - k)
    return True


@kernel(fastmath=True, inline="always")
def _eliminate(row_i, row_k, off, inv, count):
    """Subtract the multiple of pivot row ``row_k`` that zeroes ``row_i[off]`` (stored as L's entry)
    from the ``count`` entries of ``row_i`` right of it."""
    lik = row_i[off] * inv
    row_i[off] = lik
    for j in range(count):
        row_i[off + 1 + j] -= lik * row_k[BAND_HALF_WIDTH + 1 + j]


@kernel(fastmath=True)
def band_lu_solve(lu, b):
    """Solve (L U) X = B in place for a factor from :func:`band_lu`; ``b`` is (n, SOLVE_COLUMNS),
    band order (the constant column count lets the compiler unroll the column loops)."""
    n = lu.shape[0]
    w = BAND_HALF_WIDTH
    for i in range(n):
        row = lu[i]
        first = max(0, i - w)
        for j in range(first, i):
            _subtract(b[i], row[w + j - i], b[j])
    for i in range(n - 1, -1, -1):
        row = lu[i]
        last = min(n, i + w + 1)
        for j in range(i + 1, last):
            _subtract(b[i], row[w + j - i], b[j])
        inv = 1.0 / row[w]
        bi = b[i]
        for c in range(SOLVE_COLUMNS):
            bi[c] *= inv


@kernel(fastmath=True, inline="always")
def _subtract(bi, factor, bj):
    """``bi -= factor * bj`` over the ``SOLVE_COLUMNS`` columns."""
    for c in range(SOLVE_COLUMNS):
        bi[c] -= factor * bj[c]


@kernel
def _small_solve(a, b, k):
    """Solve a[:k, :k] y = b[:k] in place (Gaussian elimination, partial pivoting). False if singular."""
    for c in range(k):
        best = c
        for r in range(c + 1, k):
            if abs(a[r, c]) > abs(a[best, c]):
                best = r
        if not (abs(a[best, c]) > 1e-300):
            return False
        if best != c:
            for j in range(k):
                a[c, j], a[best, j] = a[best, j], a[c, j]
            b[c], b[best] = b[best], b[c]
        for r in range(c + 1, k):
            f = a[r, c] / a[c, c]
            for j in range(c, k):
                a[r, j] -= f * a[c, j]
            b[r] -= f * b[c]
    for r in range(k - 1, -1, -1):
        s = b[r]
        for j in range(r + 1, k):
            s -= a[r, j] * b[j]
        b[r] = s / a[r, r]
    return True


@kernel
def solve_band_low_rank(band, pos, u, v, rank, rhs, work, cap, coef):
    """Solve (B + U V^T) x = rhs in place, O(N).

    ``band`` holds B (band order) and is overwritten by its LU factor; ``u``, ``v`` are (2N, >=rank)
    in natural order; ``rhs`` (2N,) natural order is overwritten by the solution. ``work``
    (2N, SOLVE_COLUMNS), ``cap`` (MAX_LOW_RANK, MAX_LOW_RANK) and ``coef`` (MAX_LOW_RANK,) are
    scratch. Returns False if the factorisation breaks down.
    """
    if not band_lu(band):
        return False
    n_nodes = pos.shape[0]
    cols = work
    for node in range(n_nodes):
        p = 2 * pos[node]
        for d in range(2):
            cols[p + d, 0] = rhs[2 * node + d]
            for c in range(MAX_LOW_RANK):
                cols[p + d, c + 1] = u[2 * node + d, c] if c < rank else 0.0
    band_lu_solve(band, cols)
    if rank > 0:
        for a in range(rank):
            s = 0.0
            for c in range(rank):
                cap[a, c] = 1.0 if a == c else 0.0
            for node in range(n_nodes):
                p = 2 * pos[node]
                for d in range(2):
                    va = v[2 * node + d, a]
                    s += va * cols[p + d, 0]
                    for c in range(rank):
                        cap[a, c] += va * cols[p + d, c + 1]
            coef[a] = s
        if not _small_solve(cap, coef, rank):
            return False
    for node in range(n_nodes):
        p = 2 * pos[node]
        for d in range(2):
            s = cols[p + d, 0]
            for c in range(rank):
                s -= cols[p + d, c + 1] * coef[c]
            rhs[2 * node + d] = s
    return True


def band_to_dense(band, pos):
    """Dense 2N x 2N matrix (natural DOF order) of a band in zig-zag order; for tests and checks."""
    n = band.shape[0]
    w = BAND_HALF_WIDTH
    dense_band_order = np.zeros((n, n))
    for r in range(n):
        for c in range(max(0, r - w), min(n, r + w + 1)):
            dense_band_order[r, c] = band[r, w + c - r]
    dof = np.empty(n, dtype=np.int64)
    dof[0::2] = 2 * pos
    dof[1::2] = 2 * pos + 1
    return dense_band_order[np.ix_(dof, dof)]


@kernel
def _solve_columns(lu, pos, src, first, count, work, dst):
    """``dst[:, first:first + count] = B^-1 src[:, first:first + count]`` (natural order), in chunks
    of ``SOLVE_COLUMNS`` through the factor ``lu`` of :func:`band_lu`; ``work`` is scratch."""
    n_nodes = pos.shape[0]
    for start in range(first, first + count, SOLVE_COLUMNS):
        stop = min(start + SOLVE_COLUMNS, first + count)
        for node in range(n_nodes):
            p = 2 * pos[node]
            for d in range(2):
                for c in range(SOLVE_COLUMNS):
                    work[p + d, c] = src[2 * node + d, start + c] if start + c < stop else 0.0
        band_lu_solve(lu, work)
        for node in range(n_nodes):
            p = 2 * pos[node]
            for d in range(2):
                for c in range(stop - start):
                    dst[2 * node + d, start + c] = work[p + d, c]


@kernel(inline="always")
def _capacitance(v, z, n, rank, cap):
    """``cap = I + V^T Z`` (``rank`` x ``rank``) of the Woodbury identity for ``v``, ``z`` (``n`` rows,
    >= ``rank`` columns): row by row of both (their storage order; each entry still sums over the
    rows in order) and skipping the zeros of ``v`` (the barrier's columns have a few nonzeros)."""
    for a in range(rank):
        for c in range(rank):
            cap[a, c] = 1.0 if a == c else 0.0
    for k in range(n):
        for a in range(rank):
            va = v[k, a]
            if va != 0.0:
                for c in range(rank):
                    cap[a, c] += va * z[k, c]


@kernel
def solve_band_wide_low_rank(band, pos, u, v, rank, rhs, work, z, cap, coef):
    """Solve (B + U V^T) x = rhs in place for ``rank`` low-rank columns of any number (``u``, ``v``
    (2N, >= rank) natural order): the Woodbury identity with ``Z = B^-1 U`` solved in chunks,
    ``O(N (w + rank) rank + rank^3)``. ``band`` is overwritten by its LU factor, ``rhs`` (2N,) by
    the solution. Scratch: ``work`` (2N, SOLVE_COLUMNS), ``z`` (2N, >= rank + 1), ``cap``
    (>= rank, >= rank), ``coef`` (>= rank,). Returns False if the factorisation breaks down."""
    if not band_lu(band):
        return False
    n = rhs.shape[0]
    for k in range(n):
        z[k, rank] = rhs[k]  # the right-hand side rides along as the last column
        for c in range(rank):
            z[k, c] = u[k, c]
    _solve_columns(band, pos, z, 0, rank + 1, work, z)
    _capacitance(v, z, n, rank, cap)
    for a in range(rank):
        coef[a] = 0.0
    for k in range(n):  # (row by row: v is read along its rows; each sum still runs over k in order)
        zk = z[k, rank]
        for a in range(rank):
            va = v[k, a]
            if va != 0.0:
                coef[a] += va * zk
    if rank > 0 and not _small_solve(cap, coef, rank):
        return False
    for k in range(n):
        s = z[k, rank]
        for c in range(rank):
            s -= z[k, c] * coef[c]
        rhs[k] = s
    return True


@kernel
def lu_factor(a, k, piv):
    """Factorise ``a[:k, :k]`` in place (LU with partial pivoting; row swaps in ``piv``). False if
    singular."""
    for c in range(k):
        best = c
        for r in range(c + 1, k):
            if abs(a[r, c]) > abs(a[best, c]):
                best = r
        piv[c] = best
        if not (abs(a[best, c]) > 1e-300):
            return False
        if best != c:
            for j in range(k):
                a[c, j], a[best, j] = a[best, j], a[c, j]
        inv = 1.0 / a[c, c]
        for r in range(c + 1, k):
            f = a[r, c] * inv
            a[r, c] = f
            if f != 0.0:
                for j in range(c + 1, k):
                    a[r, j] -= f * a[c, j]
    return True


@kernel
def lu_solve(a, k, piv, b):
    """Solve with a factor of :func:`lu_factor`: ``b[:k]`` is overwritten by the solution."""
    for c in range(k):
        p = piv[c]
        if p != c:
            b[c], b[p] = b[p], b[c]
    for r in range(k):
        s = b[r]
        for j in range(r):
            s -= a[r, j] * b[j]
        b[r] = s
    for r in range(k - 1, -1, -1):
        s = b[r]
        for j in range(r + 1, k):
            s -= a[r, j] * b[j]
        b[r] = s / a[r, r]


@kernel
def solve_band_low_rank_columns(band, pos, u, v, rank, cols, n_cols, work, z, cap, piv, coef):
    """Solve (B + U V^T) X = C in place of the first ``n_cols`` columns of ``cols`` (2N, >= n_cols;
    natural order) for ``rank`` low-rank columns ``u``, ``v`` (2N, >= rank): the Woodbury identity
    with ``Z = B^-1 U``, the capacitance ``I + V^T Z`` factorised once for every column;
    ``O(N w^2 + N (w + rank) (rank + n_cols) + rank^3)``. ``band`` is overwritten by its LU factor.
    Scratch: ``work`` (2N, SOLVE_COLUMNS), ``z`` (2N, >= rank), ``cap`` (>= rank, >= rank), ``piv``
    (>= rank,) int, ``coef`` (>= rank,). Returns False if a factorisation breaks down."""
    if not band_lu(band):
        return False
    n = cols.shape[0]
    for k in range(n):
        for c in range(rank):
            z[k, c] = u[k, c]
    _solve_columns(band, pos, z, 0, rank, work, z)
    _solve_columns(band, pos, cols, 0, n_cols, work, cols)
    if rank == 0:
        return True
    _capacitance(v, z, n, rank, cap)
    if not lu_factor(cap, rank, piv):
        return False
    for c in range(n_cols):
        for a in range(rank):
            coef[a] = 0.0
        for k in range(n):  # (row by row, as in _capacitance; a zero term adds nothing)
            ck = cols[k, c]
            for a in range(rank):
                va = v[k, a]
                if va != 0.0:
                    coef[a] += va * ck
        lu_solve(cap, rank, piv, coef)
        for k in range(n):
            s = cols[k, c]
            for a in range(rank):
                s -= z[k, a] * coef[a]
            cols[k, c] = s
    return True
