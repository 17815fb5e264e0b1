"""The icosphere mesh of a shell: vertices, triangles, edges, hinges and lumped masses.

Subdivision ``k`` of the icosahedron (each triangle cut into four at its edges' midpoints, the new
vertices pushed onto the sphere) has ``V = 10 * 4**k + 2`` vertices, ``T = 20 * 4**k`` triangles,
``E = 30 * 4**k`` edges and, the surface being closed, one hinge per edge. Vertex 0 is the north
pole ``(0, 0, R)`` and vertex 1 the south pole ``(0, 0, -R)``. Triangles are oriented outwards:
``(x1 - x0) x (x2 - x0)`` points away from the centre.

A hinge is the edge ``(i, j)`` with the vertex ``k`` opposite it in the triangle that runs ``i -> j``
and the vertex ``l`` opposite it in the triangle that runs ``j -> i``: ``hinges[h] = (i, j, k, l)``.
"""

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray


class Mesh(NamedTuple):
    """A closed triangle mesh: positions (V, 3) m, triangles (T, 3), edges (E, 2) with i < j,
    hinges (E, 4) as (i, j, k, l) (module doc)."""

    vertices: NDArray[np.float64]
    triangles: NDArray[np.int64]
    edges: NDArray[np.int64]
    hinges: NDArray[np.int64]


def counts(subdivisions: int) -> dict[str, int]:
    """Vertices, edges, triangles and hinges of the icosphere of ``subdivisions`` k."""
    n = 4**subdivisions
    return {"vertices": 10 * n + 2, "edges": 30 * n, "triangles": 20 * n, "hinges": 30 * n}


def icosahedron() -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Unit icosahedron with vertices at the poles: (12, 3) positions and (20, 3) outward triangles."""
    z, r = 1.0 / np.sqrt(5.0), 2.0 / np.sqrt(5.0)
    upper = [(r * np.cos(2 * np.pi * m / 5), r * np.sin(2 * np.pi * m / 5), z) for m in range(5)]
    lower = [
        (r * np.cos(2 * np.pi * m / 5 + np.pi / 5), r * np.sin(2 * np.pi * m / 5 + np.pi / 5), -z)
        for m in range(5)
    ]
    vertices = np.array([(0.0, 0.0, 1.0), (0.0, 0.0, -1.0), *upper, *lower])
    faces = []
    for m in range(5):
        u0, u1 = 2 + m, 2 + (m + 1) % 5
        l0, l1 = 7 + m, 7 + (m + 1) % 5
        faces += [(0, u0, u1), (u0, l0, u1), (u1, l0, l1), (1, l1, l0)]
    return vertices, orient_outwards(vertices, np.array(faces, dtype=np.int64))


def orient_outwards(vertices: NDArray[np.float64], triangles: NDArray[np.int64]) -> NDArray[np.int64]:
    """``triangles`` with each one's order swapped where its normal points towards the origin."""
    a, b, c = (vertices[triangles[:, m]] for m in range(3))
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), a + b + c) < 0.0
    out = triangles.copy()
    out[inward, 1], out[inward, 2] = triangles[inward, 2], triangles[inward, 1]
    return out


def subdivide(
    vertices: NDArray[np.float64], triangles: NDArray[np.int64]
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """One 1-to-4 subdivision, midpoints projected onto the unit sphere (orientation kept)."""
    points = [tuple(v) for v in vertices]
    midpoint: dict[tuple[int, int], int] = {}

    def middle(i: int, j: int) -> int:
        key = (min(i, j), max(i, j))
        if key not in midpoint:
            m = (vertices[i] + vertices[j]) / 2.0
            points.append(tuple(m / np.linalg.norm(m)))
            midpoint[key] = len(points) - 1
        return midpoint[key]

    out = []
    for i, j, k in triangles.tolist():
        a, b, c = middle(i, j), middle(j, k), middle(k, i)
        out += [(i, a, c), (a, j, b), (c, b, k), (a, b, c)]
    return np.array(points, dtype=np.float64), np.array(out, dtype=np.int64)


def edges_and_hinges(
    triangles: NDArray[np.int64], n_vertices: int
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Edges (E, 2), i < j, sorted, and hinges (E, 4) of a closed, consistently oriented mesh."""
    directed = np.concatenate([triangles[:, [0, 1, 2]], triangles[:, [1, 2, 0]], triangles[:, [2, 0, 1]]])
    i, j, opposite = directed[:, 0], directed[:, 1], directed[:, 2]
    forward = i < j
    key_f = i[forward] * n_vertices + j[forward]
    key_b = j[~forward] * n_vertices + i[~forward]
    order_f, order_b = np.argsort(key_f), np.argsort(key_b)
    if key_f.size != key_b.size or not np.array_equal(key_f[order_f], key_b[order_b]):
        raise ValueError("the mesh is not closed and consistently oriented: an edge lacks its twin")
    edges = np.stack([i[forward][order_f], j[forward][order_f]], axis=1)
    hinges = np.stack(
        [edges[:, 0], edges[:, 1], opposite[forward][order_f], opposite[~forward][order_b]], axis=1
    )
    return edges, hinges


def icosphere(subdivisions: int, radius: float = 1.0) -> Mesh:
    """The icosphere of ``subdivisions`` k and ``radius`` R (m), its vertices on the sphere."""
    vertices, triangles = icosahedron()
    for _ in range(subdivisions):
        vertices, triangles = subdivide(vertices, triangles)
    edges, hinges = edges_and_hinges(triangles, len(vertices))
    return Mesh(radius * vertices, triangles, edges, hinges)


def triangle_areas(vertices: NDArray[np.float64], triangles: NDArray[np.int64]) -> NDArray[np.float64]:
    """Area (m^2) of each triangle, (T,)."""
    a, b, c = (vertices[triangles[:, m]] for m in range(3))
    return 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)


def lumped_masses(mesh: Mesh, density: float, thickness: float) -> NDArray[np.float64]:
    """Vertex masses (kg), (V,): each triangle's mass rho h A shared equally by its three vertices."""
    share = density * thickness * triangle_areas(mesh.vertices, mesh.triangles) / 3.0
    masses = np.zeros(len(mesh.vertices))
    for m in range(3):
        np.add.at(masses, mesh.triangles[:, m], share)
    return masses


def winding_numbers(
    points: NDArray[np.float64], x: NDArray[np.float64], triangles: NDArray[np.int64], chunk: int = 256
) -> NDArray[np.float64]:
    """The winding number (P,) of the closed, outward mesh ``(x, triangles)`` about each of
    ``points`` (P, 3): the triangles' solid angles seen from the point over 4 pi (1 inside, 0
    outside), each ``2 atan2(a . (b x c), |a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|)`` with ``a``,
    ``b``, ``c`` the corners relative to the point (van Oosterom and Strackee 1983); ``chunk``
    points at a time."""
    out = np.empty(len(points))
    corners = [x[triangles[:, m]][None, :, :] for m in range(3)]
    for start in range(0, len(points), chunk):
        p = points[start : start + chunk, None, :]
        a, b, c = (u - p for u in corners)
        la, lb, lc = (np.linalg.norm(u, axis=2) for u in (a, b, c))
        ab, ac, bc = (np.sum(u * w, axis=2) for u, w in ((a, b), (a, c), (b, c)))
        det = np.sum(a * np.cross(b, c), axis=2)
        angles = 2.0 * np.arctan2(det, la * lb * lc + ab * lc + ac * lb + bc * la)
        out[start : start + chunk] = angles.sum(axis=1) / (4.0 * np.pi)
    return out
