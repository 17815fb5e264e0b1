"""A flat ground under a shell: the half-space ``z >= height`` (m) and its contact barrier.

Each vertex at height ``d = z - height`` (m) above the ground is held off it by the potential of
Incremental Potential Contact (Li et al. 2020), the same scalar function as the ring's walls
(``ballenv.physics.walls.self_barrier.beta``)::

    B = kappa dhat^2 beta(d^2 / dhat^2),   beta(y) = -(y - 1)^2 ln y  (0 < y < 1; 0 for y >= 1)

(J; ``kappa`` N/m, ``dhat`` m, the distance below which it acts), with::

    dB/dz = 2 kappa d beta'(y),   d2B/dz2 = kappa (4 y beta''(y) + 2 beta'(y)),   y = d^2 / dhat^2.

``B`` is ``C^2``, zero with its first two derivatives at ``d = dhat`` and infinite at ``d = 0``, so a
state with finite energy has every vertex above the ground. A straight motion ``x + alpha dx`` keeps
every vertex above it for ``alpha <= max_step(...)`` (:func:`max_step`).
"""

import math

from ..physics.base.jit import kernel
from ..physics.walls.self_barrier import beta, beta_curvature, beta_slope

CCD_SAFETY = 0.8  # a straight motion stops at this fraction of the way to the ground


@kernel
def barrier_energy(x, height, dhat, kappa):
    """``sum_i B(z_i)`` (J); inf if a vertex is at or below the ground."""
    total = 0.0
    for i in range(x.shape[0]):
        d = x[i, 2] - height
        if d < dhat:
            total += kappa * dhat * dhat * beta(d * d / (dhat * dhat)) if d > 0.0 else math.inf
    return total


@kernel
def add_barrier(x, height, dhat, kappa, grad, diagonal):
    """Adds ``dB/dz`` (N) to ``grad[:, 2]`` and ``d2B/dz2`` (N/m) to ``diagonal[:, 2]``; returns the
    number of vertices within ``dhat`` of the ground."""
    touching = 0
    for i in range(x.shape[0]):
        d = x[i, 2] - height
        if 0.0 < d < dhat:
            y = d * d / (dhat * dhat)
            grad[i, 2] += 2.0 * kappa * d * beta_slope(y)
            diagonal[i, 2] += kappa * (4.0 * y * beta_curvature(y) + 2.0 * beta_slope(y))
            touching += 1
    return touching


@kernel
def max_step(x, dx, height):
    """The largest ``alpha <= 1`` for which ``x + alpha dx`` keeps every vertex at least
    ``1 - CCD_SAFETY`` of its height above the ground."""
    alpha = 1.0
    for i in range(x.shape[0]):
        if dx[i, 2] < 0.0:
            limit = CCD_SAFETY * (x[i, 2] - height) / -dx[i, 2]
            alpha = min(alpha, limit)
    return alpha
