"""The broad phase of contact between shells and within one: which pairs, of a vertex and a
triangle (point-triangle) or of two edges (edge-edge), may come within the barrier's reach ``dhat``
(m) during a straight motion ``x + alpha dx``, ``0 <= alpha <= 1``, of every vertex.

The shells of a group share one mesh (``T`` triangles, ``E`` edges over ``V`` vertices); a vertex is
numbered ``k V + i`` (shell ``k``, vertex ``i``) in the group's positions ``x`` (S V, 3). The boxes
of the triangles, and of the edges, around their corners at ``x`` and ``x + dx``, grown by ``dhat``,
go into two uniform grids hashed into buckets (cells of the largest triangle box's size, so that a
box meets at most 2 x 2 x 2 cells; counting sorts into preallocated arrays); each vertex's box
around ``x`` and ``x + dx`` is tested against the triangles of the buckets its cells hash to, each
edge's against the edges; without self-contact, only the elements whose boxes meet another shell's
box (around its triangles' boxes) go into the grids or are tested. A candidate is a pair whose boxes
overlap, of elements of different shells, or, with self-contact, of one shell's that share no vertex
(pairs sharing a vertex are left to the skin's own stiffness). The cost is linear in the vertices
and the candidates; a pair that is not a candidate stays farther than ``dhat`` apart along the whole
motion.
"""

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ...physics.base.jit import kernel
from .distance import EDGE_EDGE, POINT_TRIANGLE

HASH_X, HASH_Y, HASH_Z = 73856093, 19349663, 83492791  # the spatial hash's primes (Teschner et al. 2003)
CELL_MARGIN = 1.000001  # the cell against the largest box: a box meets at most two cells per axis
BUCKETS_PER_ELEMENT = 4  # a hash table's size against its elements (rounded up to a power of 2)


class Grid(NamedTuple):
    """One kind of element (triangles or edges) of every shell of a group, hashed by their boxes."""

    elements: NDArray[np.int64]  # (M, k) the mesh's elements (vertex indices within a shell)
    lo: NDArray[np.float64]  # (S M, 3) m: the elements' grown boxes
    hi: NDArray[np.float64]  # (S M, 3) m
    start: NDArray[np.int64]  # (H + 1,) each bucket's first entry in ``items``
    items: NDArray[np.int64]  # (8 S M,) elements by bucket
    fill: NDArray[np.int64]  # (H,) scratch
    stamp: NDArray[np.int64]  # (S M,) the last element queried that met each element


class Candidates(NamedTuple):
    """The grids and the candidate pairs of a group of shells."""

    triangles: Grid
    edges: Grid
    points: NDArray[np.int64]  # (V, 1) each vertex as an element
    shell_lo: NDArray[np.float64]  # (S, 3) m: each shell's box, around its triangles' boxes
    shell_hi: NDArray[np.float64]  # (S, 3) m
    pairs: NDArray[np.int64]  # (P, 5): the pair's four vertices (group numbering), its kind
    n_pairs: NDArray[np.int64]  # (1,): candidates in ``pairs``, -1 if they did not fit
    self_contact: bool


def _grid(elements: NDArray[np.int64], n_shells: int) -> Grid:
    n = n_shells * len(elements)
    buckets = 1 << int(np.ceil(np.log2(BUCKETS_PER_ELEMENT * n)))
    z, i64 = np.zeros, np.int64
    return Grid(
        np.ascontiguousarray(elements, dtype=i64), z((n, 3)), z((n, 3)), z(buckets + 1, dtype=i64),
        z(8 * n, dtype=i64), z(buckets, dtype=i64), z(n, dtype=i64),
    )  # fmt: skip


def make_candidates(
    triangles: NDArray[np.int64], edges: NDArray[np.int64], n_shells: int, capacity: int, self_contact: bool
) -> Candidates:
    """Empty records for ``n_shells`` shells of the mesh and ``capacity`` pairs."""
    points = np.arange(int(triangles.max()) + 1, dtype=np.int64)[:, None]
    pairs = np.zeros((capacity, 5), dtype=np.int64)
    n = np.zeros(1, dtype=np.int64)
    boxes = np.zeros((n_shells, 3)), np.zeros((n_shells, 3))
    grids = _grid(triangles, n_shells), _grid(edges, n_shells)
    return Candidates(*grids, points, *boxes, pairs, n, self_contact)


@kernel(inline="always")
def _bucket(ix, iy, iz, mask):
    return ((ix * HASH_X) ^ (iy * HASH_Y) ^ (iz * HASH_Z)) & mask


@kernel(inline="always")
def _cell(value, cell):
    return int(np.floor(value / cell))


@kernel
def _boxes(grid, x, dx, dhat):
    """Each element's box over the motion, grown by ``dhat``; returns the largest box side (m)."""
    el = grid.elements
    n_vertices = x.shape[0] // (grid.lo.shape[0] // el.shape[0])
    side = 0.0
    for e in range(grid.lo.shape[0]):
        base = (e // el.shape[0]) * n_vertices
        for a in range(3):
            lo, hi = np.inf, -np.inf
            for c in range(el.shape[1]):
                v = base + el[e % el.shape[0], c]
                lo = min(lo, x[v, a], x[v, a] + dx[v, a])
                hi = max(hi, x[v, a], x[v, a] + dx[v, a])
            grid.lo[e, a], grid.hi[e, a] = lo - dhat, hi + dhat
            side = max(side, hi - lo + 2.0 * dhat)
    return side


@kernel
def _shell_boxes(cd):
    """Each shell's box around its triangles' grown boxes."""
    grid = cd.triangles
    n = grid.elements.shape[0]
    cd.shell_lo[:] = np.inf
    cd.shell_hi[:] = -np.inf
    for e in range(grid.lo.shape[0]):
        k = e // n
        for a in range(3):
            cd.shell_lo[k, a] = min(cd.shell_lo[k, a], grid.lo[e, a])
            cd.shell_hi[k, a] = max(cd.shell_hi[k, a], grid.hi[e, a])


@kernel
def _near_others(cd, k, lo, hi):
    """Whether the box ``lo, hi`` meets another shell's box than ``k``'s (always, with
    self-contact): elements far from every other shell have no candidate."""
    if cd.self_contact:
        return True
    for j in range(cd.shell_lo.shape[0]):
        if j == k:
            continue
        if lo[0] <= cd.shell_hi[j, 0] and cd.shell_lo[j, 0] <= hi[0] and lo[1] <= cd.shell_hi[j, 1]:
            if cd.shell_lo[j, 1] <= hi[1] and lo[2] <= cd.shell_hi[j, 2] and cd.shell_lo[j, 2] <= hi[2]:
                return True
    return False


@kernel
def _fill(cd, grid, cell):
    """Counting sort of the elements near another shell into the buckets of the cells their boxes
    meet."""
    mask = grid.fill.shape[0] - 1
    grid.fill[:] = 0
    for stage in range(2):
        for e in range(grid.lo.shape[0]):
            lo, hi = grid.lo[e], grid.hi[e]
            if not _near_others(cd, e // grid.elements.shape[0], lo, hi):
                continue
            for ix in range(_cell(lo[0], cell), _cell(hi[0], cell) + 1):
                for iy in range(_cell(lo[1], cell), _cell(hi[1], cell) + 1):
                    for iz in range(_cell(lo[2], cell), _cell(hi[2], cell) + 1):
                        b = _bucket(ix, iy, iz, mask)
                        if stage == 1:
                            grid.items[grid.start[b] + grid.fill[b]] = e
                        grid.fill[b] += 1
        if stage == 0:
            grid.start[0] = 0
            for b in range(mask + 1):
                grid.start[b + 1] = grid.start[b] + grid.fill[b]
                grid.fill[b] = 0
    grid.stamp[:] = -1


@kernel
def _admissible(cd, grid, query, q, e, ordered):
    """Whether element ``q`` of ``query`` and ``e`` of ``grid`` (group numbering) make a pair."""
    if ordered and e <= q:
        return False
    m, n = query.shape[0], grid.elements.shape[0]
    if q // m != e // n:
        return True
    if not cd.self_contact:
        return False
    for a in range(query.shape[1]):
        for b in range(grid.elements.shape[1]):
            if query[q % m, a] == grid.elements[e % n, b]:
                return False
    return True


@kernel(inline="always")
def _overlap(lo, hi, grid, e):
    return (
        lo[0] <= grid.hi[e, 0] and grid.lo[e, 0] <= hi[0] and lo[1] <= grid.hi[e, 1]
        and grid.lo[e, 1] <= hi[1] and lo[2] <= grid.hi[e, 2] and grid.lo[e, 2] <= hi[2]
    )  # fmt: skip


@kernel
def _add(cd, grid, query, q, e, n_vertices, kind, count):
    """Writes the pair (``q``, ``e``) at ``count``; returns the new count, -1 if full."""
    if count == cd.pairs.shape[0]:
        return -1
    m, n = query.shape[0], grid.elements.shape[0]
    for a in range(query.shape[1]):
        cd.pairs[count, a] = (q // m) * n_vertices + query[q % m, a]
    for b in range(grid.elements.shape[1]):
        cd.pairs[count, query.shape[1] + b] = (e // n) * n_vertices + grid.elements[e % n, b]
    cd.pairs[count, 4] = kind
    return count + 1


@kernel
def _query(cd, grid, query, q, box, cell, kind, count, n_vertices):
    """Adds the candidates of element ``q`` of ``query`` (its box ``box`` (2, 3)) from ``count``;
    returns the new count, or -1 if they do not fit."""
    mask = grid.fill.shape[0] - 1
    lo, hi = box[0], box[1]
    for ix in range(_cell(lo[0], cell), _cell(hi[0], cell) + 1):
        for iy in range(_cell(lo[1], cell), _cell(hi[1], cell) + 1):
            for iz in range(_cell(lo[2], cell), _cell(hi[2], cell) + 1):
                b = _bucket(ix, iy, iz, mask)
                for k in range(grid.start[b], grid.start[b + 1]):
                    e = grid.items[k]
                    if grid.stamp[e] == q:
                        continue
                    grid.stamp[e] = q
                    if not _admissible(cd, grid, query, q, e, kind == EDGE_EDGE):
                        continue
                    if _overlap(lo, hi, grid, e):
                        count = _add(cd, grid, query, q, e, n_vertices, kind, count)
                        if count < 0:
                            return -1
    return count


@kernel
def _sweep(cd, grid, query, x, dx, cell, kind, count, box):
    """The candidates of every element of ``query`` (of every shell) against ``grid``."""
    n_shells = grid.lo.shape[0] // grid.elements.shape[0]
    n_vertices = x.shape[0] // n_shells
    for q in range(n_shells * query.shape[0]):
        base = (q // query.shape[0]) * n_vertices
        for a in range(3):
            box[0, a], box[1, a] = np.inf, -np.inf
            for c in range(query.shape[1]):
                v = base + query[q % query.shape[0], c]
                box[0, a] = min(box[0, a], x[v, a], x[v, a] + dx[v, a])
                box[1, a] = max(box[1, a], x[v, a], x[v, a] + dx[v, a])
        if not _near_others(cd, q // query.shape[0], box[0], box[1]):
            continue
        count = _query(cd, grid, query, q, box, cell, kind, count, n_vertices)
        if count < 0:
            return -1
    return count


@kernel
def find_pairs(cd, x, dx, dhat, box):
    """The candidate pairs (module doc) of the motion ``x + alpha dx`` (S V, 3) m into ``cd.pairs``;
    their number into ``cd.n_pairs`` and returned (-1: more than ``cd.pairs`` holds). ``box`` (2, 3)
    scratch."""
    side = _boxes(cd.triangles, x, dx, dhat)
    _boxes(cd.edges, x, dx, dhat)
    for v in range(x.shape[0]):
        for a in range(3):
            side = max(side, abs(dx[v, a]))
    cell = CELL_MARGIN * side
    _shell_boxes(cd)
    _fill(cd, cd.triangles, cell)
    _fill(cd, cd.edges, cell)
    count = _sweep(cd, cd.triangles, cd.points, x, dx, cell, POINT_TRIANGLE, 0, box)
    if count >= 0:
        count = _sweep(cd, cd.edges, cd.edges.elements, x, dx, cell, EDGE_EDGE, count, box)
    cd.n_pairs[0] = count
    return count
