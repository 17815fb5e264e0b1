"""A shell's Hessian assembled as a block-sparse matrix: 3 x 3 blocks (N/m), one per pair of
vertices that share a triangle or a hinge, stored by block rows (block CSR).

Vertex ``v``'s blocks are ``values[row_start[v]:row_start[v + 1]]`` in the columns ``cols`` of the
same range, sorted, its diagonal block at ``diagonal_slot[v]``. The pattern is built once per mesh
with, for each element, the slot of each of its vertex pairs (``tri_slots`` (T, 3, 3),
``hinge_slots`` (E, 4, 4)), so that assembling is one pass over the element matrices and a product
``y = A x`` one pass over the blocks (on the default mesh about 13 blocks per vertex against the
elements' 81 + 144 entries per triangle and hinge: a fifth of the element-by-element work).
"""

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ...physics.base.jit import kernel


class BlockPattern(NamedTuple):
    """Where each block of a mesh's matrix is stored (module doc)."""

    row_start: NDArray[np.int64]  # (V + 1,)
    cols: NDArray[np.int64]  # (B,)
    diagonal_slot: NDArray[np.int64]  # (V,)
    tri_slots: NDArray[np.int64]  # (T, 3, 3)
    hinge_slots: NDArray[np.int64]  # (E, 4, 4)


def block_pattern(n_vertices: int, triangles: NDArray[np.int64], hinges: NDArray[np.int64]) -> BlockPattern:
    """The pattern of the matrices of the mesh with ``triangles`` (T, 3) and ``hinges`` (E, 4)."""
    pairs = [np.stack([np.arange(n_vertices)] * 2, axis=1)]
    for group in (triangles, hinges):
        n = group.shape[1]
        pairs.append(np.stack([np.repeat(group, n, axis=1).ravel(), np.tile(group, (1, n)).ravel()], axis=1))
    keys = np.unique(np.concatenate(pairs) @ np.array([n_vertices, 1]))  # sorted by row, then column
    rows, cols = keys // n_vertices, keys % n_vertices
    row_start = np.searchsorted(rows, np.arange(n_vertices + 1))

    def slots(group: NDArray[np.int64]) -> NDArray[np.int64]:
        n = group.shape[1]
        key = group[:, :, None] * n_vertices + group[:, None, :]
        return np.searchsorted(keys, key.reshape(-1)).reshape(len(group), n, n)

    diagonal = np.searchsorted(keys, np.arange(n_vertices) * (n_vertices + 1))
    return BlockPattern(row_start, cols, diagonal, slots(triangles), slots(hinges))


@kernel
def _scatter(slots, mats, scale, values):
    """Adds ``scale`` times each element's matrix (rows ``3 m + c`` for its vertex m) to ``values``."""
    n = slots.shape[1]
    for e in range(slots.shape[0]):
        for a in range(n):
            for b in range(n):
                k = slots[e, a, b]
                for c in range(3):
                    for d in range(3):
                        values[k, c, d] += scale * mats[e, 3 * a + c, 3 * b + d]


@kernel
def assemble(pattern, tri_mats, hinge_mats, scale, values):
    """``values`` (B, 3, 3) = ``scale`` (triangles' + hinges' matrices)."""
    values[:] = 0.0
    _scatter(pattern.tri_slots, tri_mats, scale, values)
    _scatter(pattern.hinge_slots, hinge_mats, scale, values)


@kernel
def assemble_hinges(pattern, hinge_mats, out):
    """``out`` (B, 3, 3) = the hinges' matrices alone (kept while they are, :func:`assemble_kept`)."""
    out[:] = 0.0
    _scatter(pattern.hinge_slots, hinge_mats, 1.0, out)


@kernel
def assemble_kept(pattern, tri_mats, hinge_values, scale, values):
    """``values`` (B, 3, 3) = ``scale`` (triangles' matrices + ``hinge_values``, the hinges' part
    assembled by :func:`assemble_hinges`)."""
    for k in range(values.shape[0]):
        for c in range(3):
            for d in range(3):
                values[k, c, d] = scale * hinge_values[k, c, d]
    _scatter(pattern.tri_slots, tri_mats, scale, values)


@kernel(fastmath=True)
def multiply(pattern, values, x, y):
    """``y = A x`` (V, 3)."""
    for v in range(x.shape[0]):
        y0 = y1 = y2 = 0.0
        for k in range(pattern.row_start[v], pattern.row_start[v + 1]):
            w = pattern.cols[k]
            x0, x1, x2 = x[w, 0], x[w, 1], x[w, 2]
            y0 += values[k, 0, 0] * x0 + values[k, 0, 1] * x1 + values[k, 0, 2] * x2
            y1 += values[k, 1, 0] * x0 + values[k, 1, 1] * x1 + values[k, 1, 2] * x2
            y2 += values[k, 2, 0] * x0 + values[k, 2, 1] * x1 + values[k, 2, 2] * x2
        y[v, 0], y[v, 1], y[v, 2] = y0, y1, y2
