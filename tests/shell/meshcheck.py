"""Independent geometric checks of intersection-freeness for the contact tests (NumPy, brute
force): the generalized winding number of points about a closed mesh (ballenv.shell.skin.mesh, tested
in skin/test_mesh.py), segment-triangle crossings and point-triangle distances (by the plane and the
three edges, not by feature regions)."""

import numpy as np

from ballenv.shell.skin.mesh import winding_numbers


def edges_of(triangles):
    e = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    return np.unique(np.sort(e, axis=1), axis=0)


def segment_crossings(p, q, x, triangles):
    """How many segments ``p -> q`` (E, 3) cross a triangle of the mesh (Moller-Trumbore)."""
    a, b, c = x[triangles[:, 0]], x[triangles[:, 1]], x[triangles[:, 2]]
    d = (q - p)[:, None]
    e1, e2 = (b - a)[None], (c - a)[None]
    h = np.cross(d, e2)
    det = np.einsum("etk,etk->et", e1, h)
    s = p[:, None] - a[None]
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.einsum("etk,etk->et", s, h) / det
        qv = np.cross(s, e1)
        v = np.einsum("etk,etk->et", d, qv) / det
        t = np.einsum("etk,etk->et", e2, qv) / det
        hit = (np.abs(det) > 0) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= 0) & (t <= 1)
    return int(hit.sum())


def _segment_distance(p, a, b):
    ab = b - a
    t = np.clip(np.einsum("...k,...k->...", p - a, ab) / np.einsum("...k,...k->...", ab, ab), 0.0, 1.0)
    return np.linalg.norm(p - a - t[..., None] * ab, axis=-1)


def point_triangle_distances(points, x, triangles):
    """The distances (P, T) m between the points (P, 3) and the triangles of the mesh."""
    p = points[:, None]
    a, b, c = (x[triangles[:, k]][None] for k in range(3))
    n = np.cross(b - a, c - a)
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    h = np.einsum("ptk,ptk->pt", p - a, n)
    foot = p - h[..., None] * n
    inside = np.ones(h.shape, dtype=bool)
    for u, w in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("ptk,ptk->pt", np.cross(w - u, foot - u), n) >= 0
    edge = np.minimum(
        np.minimum(_segment_distance(p, a, b), _segment_distance(p, b, c)), _segment_distance(p, c, a)
    )
    return np.where(inside, np.abs(h), edge)


def min_point_triangle_distance(points, x, triangles):
    """The smallest distance (m) between the points (P, 3) and the triangles of the mesh."""
    return float(point_triangle_distances(points, x, triangles).min())


def check_apart(xa, xb, triangles):
    """``(largest winding number of a vertex of either about the other, edge crossings, smallest
    vertex-triangle distance m)`` of two shells' vertices (V, 3) on the mesh ``triangles``."""
    edges = edges_of(triangles)
    wind = max(winding_numbers(xa, xb, triangles).max(), winding_numbers(xb, xa, triangles).max())
    cross = segment_crossings(xa[edges[:, 0]], xa[edges[:, 1]], xb, triangles)
    cross += segment_crossings(xb[edges[:, 0]], xb[edges[:, 1]], xa, triangles)
    low = min(min_point_triangle_distance(xa, xb, triangles), min_point_triangle_distance(xb, xa, triangles))
    return float(wind), cross, low


def check_self(x, triangles):
    """``(crossings of an edge and a triangle sharing no vertex, smallest distance m of a vertex
    from a triangle that does not hold it)`` of one shell's vertices (V, 3)."""
    edges = edges_of(triangles)
    a, b, c = x[triangles[:, 0]], x[triangles[:, 1]], x[triangles[:, 2]]
    p, q = x[edges[:, 0]], x[edges[:, 1]]
    d = (q - p)[:, None]
    e1, e2 = (b - a)[None], (c - a)[None]
    h = np.cross(d, e2)
    det = np.einsum("etk,etk->et", e1, h)
    s = p[:, None] - a[None]
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.einsum("etk,etk->et", s, h) / det
        qv = np.cross(s, e1)
        v = np.einsum("etk,etk->et", d, qv) / det
        t = np.einsum("etk,etk->et", e2, qv) / det
        hit = (np.abs(det) > 0) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= 0) & (t <= 1)
    shared = (edges[:, None, :, None] == triangles[None, :, None, :]).any(axis=(2, 3))
    crossings = int((hit & ~shared).sum())
    distances = point_triangle_distances(x, x, triangles)
    holds = (np.arange(len(x))[:, None, None] == triangles[None]).any(axis=2)
    return crossings, float(distances[~holds].min())
