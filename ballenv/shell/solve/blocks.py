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
from numba import uint64
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
    """Adds ``scale`` times each element's matrix (rows ``3 m + c`` for its vertex m) to ``values``,
    read and written as flat arrays at unsigned offsets (:func:`multiply`)."""
    n = uint64(slots.shape[1])
    row = uint64(3) * n  # an element matrix's row length
    flat, elements = values.reshape(values.size), mats.reshape(mats.size)
    for e in range(uint64(slots.shape[0])):
        for a in range(n):
            for b in range(n):
                k = uint64(9) * uint64(slots[e, a, b])
                start = (e * row + uint64(3) * a) * row + uint64(3) * b
                for c in range(uint64(3)):
                    for d in range(uint64(3)):
                        flat[k + uint64(3) * c + d] += scale * elements[start + c * row + d]


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
    """``y = A x`` (V, 3). The blocks and ``x`` (both C-contiguous) are read as flat arrays at
    unsigned offsets: numba tests every signed index for a negative value (Python's ``a[-1]``) and
    corrects it, an unsigned one not; the sums are the same, term for term."""
    flat, xf = values.reshape(values.size), x.reshape(x.size)
    one, two, three, nine = uint64(1), uint64(2), uint64(3), uint64(9)
    for v in range(x.shape[0]):
        y0 = y1 = y2 = 0.0
        for k in range(uint64(pattern.row_start[v]), uint64(pattern.row_start[v + 1])):
            w, b = three * uint64(pattern.cols[k]), nine * k
            x0, x1, x2 = xf[w], xf[w + one], xf[w + two]
            y0 += flat[b] * x0 + flat[b + one] * x1 + flat[b + two] * x2
            y1 += flat[b + three] * x0 + flat[b + uint64(4)] * x1 + flat[b + uint64(5)] * x2
            y2 += flat[b + uint64(6)] * x0 + flat[b + uint64(7)] * x1 + flat[b + uint64(8)] * x2
        y[v, 0], y[v, 1], y[v, 2] = y0, y1, y2
