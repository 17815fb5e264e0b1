"""The broad phase of contact between shells and within one: which (vertex, triangle) pairs may
come within the barrier's reach ``dhat`` (m) during a straight motion ``x + alpha dx``,
``0 <= alpha <= 1``, of every vertex.

The shells of a group share one mesh (``T`` triangles over ``V`` vertices); a vertex is numbered
``k V + i`` (shell ``k``, vertex ``i``) in the group's positions ``x`` (S V, 3). Each triangle's box
around its corners at ``x`` and ``x + dx``, grown by ``dhat``, goes into a uniform grid hashed into
``H`` buckets (cells of the largest box's size, so that a box meets at most 2 x 2 x 2 cells; a
counting sort into preallocated arrays); each vertex's box around ``x`` and ``x + dx`` is tested
against the triangles of the buckets its cells hash to. A candidate is a pair whose boxes overlap,
of a vertex and a triangle of another shell, or, with self-contact, of its own shell that does not
hold it (pairs sharing a vertex are left to the skin's own stiffness). The cost is linear in the
vertices and the candidates; a pair that is not a candidate stays farther than ``dhat`` apart along
the whole motion.
"""

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ..physics.base.jit import kernel

HASH_X, HASH_Y, HASH_Z = 73856093, 19349663, 83492791  # the spatial hash's primes (Teschner et al. 2003)
CELL_MARGIN = 1.000001  # the cell against the largest box: a box meets at most two cells per axis
BUCKETS_PER_TRIANGLE = 4  # the hash table's size against the triangles (rounded up to a power of 2)


class Candidates(NamedTuple):
    """The grid and the candidate pairs of a group of shells."""

    triangles: NDArray[np.int64]  # (T, 3) the shared mesh
    lo: NDArray[np.float64]  # (S T, 3) m: the triangles' grown boxes
    hi: NDArray[np.float64]  # (S T, 3) m
    start: NDArray[np.int64]  # (H + 1,) each bucket's first entry in ``items``
    items: NDArray[np.int64]  # (8 S T,) triangles by bucket
    fill: NDArray[np.int64]  # (H,) scratch
    stamp: NDArray[np.int64]  # (S T,) the last vertex that met each triangle
    pairs: NDArray[np.int64]  # (P, 4): vertex, then the triangle's corners (group numbering)
    n_pairs: NDArray[np.int64]  # (1,): candidates in ``pairs``, -1 if they did not fit
    self_contact: bool


def make_candidates(
    triangles: NDArray[np.int64], n_shells: int, capacity: int, self_contact: bool
) -> Candidates:
    """Empty records for ``n_shells`` shells of the mesh ``triangles`` and ``capacity`` pairs."""
    n = n_shells * len(triangles)
    buckets = 1 << int(np.ceil(np.log2(BUCKETS_PER_TRIANGLE * n)))
    z, i64 = np.zeros, np.int64
    return Candidates(
        np.ascontiguousarray(triangles, dtype=i64), z((n, 3)), z((n, 3)), z(buckets + 1, dtype=i64),
        z(8 * n, dtype=i64), z(buckets, dtype=i64), z(n, dtype=i64), z((capacity, 4), dtype=i64),
        z(1, dtype=i64), self_contact,
    )  # fmt: skip


@kernel(inline="always")
def _bucket(ix, iy, iz, mask):
    return ((ix * HASH_X) ^ (iy * HASH_Y) ^ (iz * HASH_Z)) & mask


@kernel
def _triangle_boxes(cd, x, dx, dhat):
    """Each triangle's box over the motion, grown by ``dhat``; returns the largest box side (m)."""
    tri, n_vertices = cd.triangles, x.shape[0] // (cd.lo.shape[0] // cd.triangles.shape[0])
    side = 0.0
    for e in range(cd.lo.shape[0]):
        base = (e // tri.shape[0]) * n_vertices
        t = e % tri.shape[0]
        for a in range(3):
            lo, hi = np.inf, -np.inf
            for c in range(3):
                v = base + tri[t, c]
                lo = min(lo, x[v, a], x[v, a] + dx[v, a])
                hi = max(hi, x[v, a], x[v, a] + dx[v, a])
            cd.lo[e, a], cd.hi[e, a] = lo - dhat, hi + dhat
            side = max(side, hi - lo + 2.0 * dhat)
    for v in range(x.shape[0]):
        for a in range(3):
            side = max(side, abs(dx[v, a]))
    return side


@kernel(inline="always")
def _cell(value, cell):
    return int(np.floor(value / cell))


@kernel
def _fill_grid(cd, cell):
    """Counting sort of the triangles into the buckets of the cells their boxes meet."""
    mask = cd.fill.shape[0] - 1
    cd.fill[:] = 0
    for stage in range(2):
        for e in range(cd.lo.shape[0]):
            lo, hi = cd.lo[e], cd.hi[e]
            for ix in range(_cell(lo[0], cell), _cell(hi[0], cell) + 1):
                for iy in range(_cell(lo[1], cell), _cell(hi[1], cell) + 1):
                    for iz in range(_cell(lo[2], cell), _cell(hi[2], cell) + 1):
                        b = _bucket(ix, iy, iz, mask)
                        if stage == 1:
                            cd.items[cd.start[b] + cd.fill[b]] = e
                        cd.fill[b] += 1
        if stage == 0:
            cd.start[0] = 0
            for b in range(mask + 1):
                cd.start[b + 1] = cd.start[b] + cd.fill[b]
                cd.fill[b] = 0


@kernel(inline="always")
def _admissible(cd, v, e, n_vertices):
    """Whether vertex ``v`` and triangle ``e`` (group numbering) make a pair (module doc)."""
    n_triangles = cd.triangles.shape[0]
    if v // n_vertices != e // n_triangles:
        return True
    if not cd.self_contact:
        return False
    i, t = v % n_vertices, e % n_triangles
    return cd.triangles[t, 0] != i and cd.triangles[t, 1] != i and cd.triangles[t, 2] != i


@kernel
def _query(cd, x, dx, v, lo, hi, cell, count):
    """Adds vertex ``v``'s candidates to ``cd.pairs`` from ``count``; returns the new count, or -1
    if they do not fit."""
    mask = cd.fill.shape[0] - 1
    n_triangles = cd.triangles.shape[0]
    n_vertices = x.shape[0] // (cd.lo.shape[0] // n_triangles)
    for ix in range(_cell(lo[0], cell), _cell(hi[0], cell) + 1):
        for iy in range(_cell(lo[1], cell), _cell(hi[1], cell) + 1):
            for iz in range(_cell(lo[2], cell), _cell(hi[2], cell) + 1):
                b = _bucket(ix, iy, iz, mask)
                for k in range(cd.start[b], cd.start[b + 1]):
                    e = cd.items[k]
                    if cd.stamp[e] == v or not _admissible(cd, v, e, n_vertices):
                        continue
                    cd.stamp[e] = v
                    if not (lo[0] <= cd.hi[e, 0] and cd.lo[e, 0] <= hi[0] and lo[1] <= cd.hi[e, 1]):
                        continue
                    if not (cd.lo[e, 1] <= hi[1] and lo[2] <= cd.hi[e, 2] and cd.lo[e, 2] <= hi[2]):
                        continue
                    if count == cd.pairs.shape[0]:
                        return -1
                    base = (e // n_triangles) * n_vertices
                    cd.pairs[count, 0] = v
                    for c in range(3):
                        cd.pairs[count, 1 + c] = base + cd.triangles[e % n_triangles, c]
                    count += 1
    return count


@kernel
def find_pairs(cd, x, dx, dhat, box):
    """The candidate pairs (module doc) of the motion ``x + alpha dx`` (S V, 3) m into ``cd.pairs``;
    their number into ``cd.n_pairs`` and returned (-1: more than ``cd.pairs`` holds). ``box`` (2, 3)
    scratch."""
    cell = CELL_MARGIN * _triangle_boxes(cd, x, dx, dhat)
    _fill_grid(cd, cell)
    cd.stamp[:] = -1
    count = 0
    for v in range(x.shape[0]):
        for a in range(3):
            box[0, a] = min(x[v, a], x[v, a] + dx[v, a])
            box[1, a] = max(x[v, a], x[v, a] + dx[v, a])
        count = _query(cd, x, dx, v, box[0], box[1], cell, count)
        if count < 0:
            break
    cd.n_pairs[0] = count
    return count
