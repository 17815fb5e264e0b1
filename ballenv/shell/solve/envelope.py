"""The sparse symmetric linear solve of a shell's Newton systems: envelope (skyline) Cholesky after
a reverse Cuthill-McKee ordering, with the gas's rank-one term by Sherman-Morrison.

The matrix couples the three degrees of freedom of a vertex with those of every vertex that shares
a triangle or a hinge with it. The vertices are renumbered once per mesh by reverse Cuthill-McKee
(:func:`rcm_order`), which keeps every vertex's neighbours close to it in the new order; degree of
freedom ``3 pos[v] + c`` then has its lower-triangle entries in one contiguous row segment from
column ``first[r]`` to the diagonal (the envelope), stored row after row in ``values`` from
``start[r]``. The Cholesky factor ``L`` (``A = L L^T``) has the same envelope, so it is computed in
place (:func:`cholesky`, row by row: ``L_ij = (A_ij - sum_k L_ik L_jk) / L_jj`` over the rows'
common span). A non-positive pivot is reported (the matrix is not positive definite).

The rank-one part ``s u u^T`` (``s >= 0``) is solved exactly without entering the envelope::

    (A + s u u^T)^-1 r = y - z s (u . y) / (1 + s u . z),   y = A^-1 r,  z = A^-1 u.

Fixed degrees of freedom have identity rows and columns; their right-hand side is taken as zero.
"""

from collections import deque
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ...physics.base.jit import kernel


class Envelope(NamedTuple):
    """The envelope structure of a mesh's matrices and the storage of one matrix or its factor."""

    pos: NDArray[np.int64]  # (V,) position of each vertex in the new order
    first: NDArray[np.int64]  # (3V,) first column of each row (new order)
    start: NDArray[np.int64]  # (3V + 1,) where each row starts in values
    values: NDArray[np.float64]  # (start[-1],)
    work: NDArray[np.float64]  # (2, 3V) scratch of the solves


def vertex_neighbours(
    n_vertices: int, triangles: NDArray[np.int64], hinges: NDArray[np.int64]
) -> list[set[int]]:
    """Each vertex's neighbours in the matrix: the vertices of its triangles and of its hinges."""
    out: list[set[int]] = [set() for _ in range(n_vertices)]
    for group in (triangles, hinges):
        for row in group.tolist():
            for a in row:
                out[a].update(row)
    for v in range(n_vertices):
        out[v].discard(v)
    return out


def _bfs_levels(neighbours: list[set[int]], root: int) -> list[int]:
    """Vertices in breadth-first order from ``root``, neighbours by increasing degree."""
    seen = {root}
    order = [root]
    queue = deque([root])
    while queue:
        v = queue.popleft()
        for w in sorted(neighbours[v] - seen, key=lambda u: (len(neighbours[u]), u)):
            seen.add(w)
            order.append(w)
            queue.append(w)
    return order


def rcm_order(neighbours: list[set[int]]) -> NDArray[np.int64]:
    """Reverse Cuthill-McKee: the new position of each vertex (a connected graph), started from a
    pseudo-peripheral vertex (the last one reached from vertex 0, then from that one)."""
    root = _bfs_levels(neighbours, 0)[-1]
    order = _bfs_levels(neighbours, root)[::-1]
    if len(order) != len(neighbours):
        raise ValueError("the mesh's vertex graph is not connected")
    pos = np.empty(len(order), dtype=np.int64)
    pos[np.array(order)] = np.arange(len(order))
    return pos


def build_envelope(n_vertices: int, triangles: NDArray[np.int64], hinges: NDArray[np.int64]) -> Envelope:
    """The envelope of the matrices of a mesh (its ordering computed here, once)."""
    neighbours = vertex_neighbours(n_vertices, triangles, hinges)
    pos = rcm_order(neighbours)
    lowest = np.array([min([pos[w] for w in neighbours[v]] + [pos[v]]) for v in range(n_vertices)])
    first = np.empty(3 * n_vertices, dtype=np.int64)
    for c in range(3):
        first[3 * pos + c] = 3 * lowest
    rows = np.arange(3 * n_vertices)
    start = np.zeros(3 * n_vertices + 1, dtype=np.int64)
    np.cumsum(rows - first + 1, out=start[1:])
    return Envelope(pos, first, start, np.zeros(start[-1]), np.zeros((2, 3 * n_vertices)))


@kernel(inline="always")
def _add(env, r, c, value):
    if c <= r:
        env.values[env.start[r] + c - env.first[r]] += value


@kernel
def _scatter(env, elements, mats, free):
    """Adds each element's matrix (rows ``3 m + c`` for its vertex m) to the envelope's lower part,
    skipping fixed degrees of freedom."""
    n_v = elements.shape[1]
    for e in range(elements.shape[0]):
        for a in range(n_v):
            pa = 3 * env.pos[elements[e, a]]
            for b in range(n_v):
                pb = 3 * env.pos[elements[e, b]]
                if pb > pa + 2:
                    continue
                for c in range(3):
                    if not free[elements[e, a], c]:
                        continue
                    for d in range(3):
                        if free[elements[e, b], d]:
                            _add(env, pa + c, pb + d, mats[e, 3 * a + c, 3 * b + d])


@kernel
def assemble(env, triangles, tri_mats, hinges, hinge_mats, diagonal, free):
    """The envelope's values = the sum of the element matrices plus ``diagonal`` (V, 3) on the
    diagonal; a fixed degree of freedom (``free[v, c]`` False) gets an identity row and column."""
    env.values[:] = 0.0
    _scatter(env, triangles, tri_mats, free)
    _scatter(env, hinges, hinge_mats, free)
    for v in range(free.shape[0]):
        for c in range(3):
            r = 3 * env.pos[v] + c
            if free[v, c]:
                _add(env, r, r, diagonal[v, c])
            else:
                _add(env, r, r, 1.0)


@kernel(fastmath=True, inline="always")
def _dot(values, i0, j0, count):
    s = 0.0
    for k in range(count):
        s += values[i0 + k] * values[j0 + k]
    return s


@kernel(fastmath=True)
def cholesky(env):
    """Factorises the envelope's matrix in place, ``A = L L^T``; False on a non-positive pivot."""
    first, start, values = env.first, env.start, env.values
    for i in range(first.shape[0]):
        fi, si = first[i], start[i]
        for j in range(fi, i):
            fj, sj = first[j], start[j]
            k0 = max(fi, fj)
            s = values[si + j - fi] - _dot(values, si + k0 - fi, sj + k0 - fj, j - k0)
            values[si + j - fi] = s / values[sj + j - fj]
        d = values[si + i - fi] - _dot(values, si, si, i - fi)
        if not (d > 0.0) or not np.isfinite(d):
            return False
        values[si + i - fi] = np.sqrt(d)
    return True


@kernel
def cholesky_solve(env, free, rhs, out):
    """``out`` (V, 3) = A^-1 ``rhs`` (V, 3) with the factor in ``env`` (fixed entries: zero)."""
    first, start, values = env.first, env.start, env.values
    y = env.work[0]
    for v in range(rhs.shape[0]):
        for c in range(3):
            y[3 * env.pos[v] + c] = rhs[v, c] if free[v, c] else 0.0
    for i in range(y.shape[0]):
        fi, si = first[i], start[i]
        s = y[i]
        for k in range(fi, i):
            s -= values[si + k - fi] * y[k]
        y[i] = s / values[si + i - fi]
    for i in range(y.shape[0] - 1, -1, -1):
        fi, si = first[i], start[i]
        xi = y[i] / values[si + i - fi]
        y[i] = xi
        for k in range(fi, i):
            y[k] -= values[si + k - fi] * xi
    for v in range(rhs.shape[0]):
        for c in range(3):
            out[v, c] = y[3 * env.pos[v] + c]


@kernel
def solve_rank_one(env, free, s, u, rhs, out, z):
    """``out`` = (A + s u u^T)^-1 ``rhs`` over the free degrees of freedom (Sherman-Morrison) with
    the factor of A in ``env``; ``z`` (V, 3) scratch (A^-1 u)."""
    cholesky_solve(env, free, rhs, out)
    if s == 0.0:
        return
    cholesky_solve(env, free, u, z)
    uy = 0.0
    uz = 0.0
    for v in range(u.shape[0]):
        for c in range(3):
            if free[v, c]:
                uy += u[v, c] * out[v, c]
                uz += u[v, c] * z[v, c]
    f = s * uy / (1.0 + s * uz)
    for v in range(u.shape[0]):
        for c in range(3):
            out[v, c] -= f * z[v, c]
