"""Grounds under a shell: half-spaces ``n_g . x >= h_g`` (unit normal n_g, height h_g in m) and
their contact barrier.

A vertex at distance ``d = n . x - h`` (m) from a ground is held off it by the potential of
Incremental Potential Contact (Li et al. 2020), the same scalar function as the ring's walls
(``ballenv.physics.walls.self_barrier.beta``)::

    B = kappa dhat^2 beta(d^2 / dhat^2),   beta(y) = -(y - 1)^2 ln y  (0 < y < 1; 0 for y >= 1)

(J; ``kappa`` N/m, ``dhat`` m, the distance below which it acts), with::

    grad B = 2 kappa d beta'(y) n,   Hess B = kappa (4 y beta''(y) + 2 beta'(y)) n n^T,   y = d^2 / dhat^2.

``B`` is ``C^2``, zero with its first two derivatives at ``d = dhat`` and infinite at ``d = 0``, so a
state with finite energy has every vertex above every ground. A straight motion ``x + alpha dx``
keeps every vertex above them for ``alpha <= max_step(...)``. The normal force a ground pushes a
vertex with is ``lambda = -dB/dd = -2 kappa d beta'(y) >= 0`` (N).
"""

import math

from ...physics.base.jit import kernel
from ...physics.walls.self_barrier import beta, beta_curvature, beta_slope

CCD_SAFETY = 0.8  # a straight motion stops at this fraction of the way to a ground


@kernel(inline="always")
def distance(x, i, normals, heights, g):
    """``d = n_g . x_i - h_g`` (m) of vertex ``i`` from ground ``g``."""
    return normals[g, 0] * x[i, 0] + normals[g, 1] * x[i, 1] + normals[g, 2] * x[i, 2] - heights[g]


@kernel(inline="always")
def barrier(d, dhat, kappa):
    """``B`` (J) of a vertex at distance ``0 < d < dhat`` (m) (module doc)."""
    return kappa * dhat * dhat * beta(d * d / (dhat * dhat))


@kernel(inline="always")
def barrier_derivatives(d, dhat, kappa):
    """``(dB/dd (N), d^2B/dd^2 (N/m))`` of a vertex at distance ``0 < d < dhat`` (m) (module doc)."""
    y = d * d / (dhat * dhat)
    return 2.0 * kappa * d * beta_slope(y), kappa * (4.0 * y * beta_curvature(y) + 2.0 * beta_slope(y))


@kernel
def barrier_energy(x, normals, heights, dhat, kappa):
    """``sum_i sum_g B(d_ig)`` (J); inf if a vertex is at or below a ground."""
    total = 0.0
    for g in range(normals.shape[0]):
        for i in range(x.shape[0]):
            d = distance(x, i, normals, heights, g)
            if d < dhat:
                total += barrier(d, dhat, kappa) if d > 0.0 else math.inf
    return total


@kernel
def add_barrier(x, normals, heights, dhat, kappa, grad, blocks):
    """Adds ``grad B`` (N) to ``grad`` (V, 3) and ``Hess B`` (N/m) to the vertex blocks ``blocks``
    (V, 3, 3); returns the number of vertex-ground pairs within ``dhat``."""
    touching = 0
    for g in range(normals.shape[0]):
        for i in range(x.shape[0]):
            d = distance(x, i, normals, heights, g)
            if 0.0 < d < dhat:
                slope, curvature = barrier_derivatives(d, dhat, kappa)
                for a in range(3):
                    grad[i, a] += slope * normals[g, a]
                    for b in range(3):
                        blocks[i, a, b] += curvature * normals[g, a] * normals[g, b]
                touching += 1
    return touching


@kernel
def normal_forces(x, normals, heights, dhat, kappa, out):
    """``out[i, g]`` = the normal force ``lambda`` (N) of ground g on vertex i (0 beyond ``dhat``)."""
    for g in range(normals.shape[0]):
        for i in range(x.shape[0]):
            d = distance(x, i, normals, heights, g)
            out[i, g] = -2.0 * kappa * d * beta_slope(d * d / (dhat * dhat)) if 0.0 < d < dhat else 0.0


@kernel
def min_distance(x, normals, heights):
    """The smallest distance (m) of a vertex from a ground (inf without grounds)."""
    low = math.inf
    for g in range(normals.shape[0]):
        for i in range(x.shape[0]):
            low = min(low, distance(x, i, normals, heights, g))
    return low


@kernel
def max_step(x, dx, normals, heights):
    """The largest ``alpha <= 1`` for which ``x + alpha dx`` keeps every vertex at least
    ``1 - CCD_SAFETY`` of its distance from every ground."""
    alpha = 1.0
    for g in range(normals.shape[0]):
        for i in range(x.shape[0]):
            rate = normals[g, 0] * dx[i, 0] + normals[g, 1] * dx[i, 1] + normals[g, 2] * dx[i, 2]
            if rate < 0.0:
                alpha = min(alpha, CCD_SAFETY * distance(x, i, normals, heights, g) / -rate)
    return alpha
