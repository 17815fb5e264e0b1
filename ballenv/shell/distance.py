"""The distance between a point and a triangle in 3-D, with its exact gradient and Hessian.

For a point ``p`` and a triangle ``(a, b, c)`` (m) the closest point of the triangle lies on one of
its seven features (Ericson, *Real-Time Collision Detection*, 5.1.5): a vertex, an edge or the face.
On a feature spanned by ``s_0, ..., s_k`` (k = 0, 1, 2) the closest point is
``q = s_0 + sum_j theta_j (s_j - s_0)`` with the parameters ``theta`` that minimise

    f(x, theta) = |r|^2,   r = p - q = sum_m w_m x_m                                   (m^2)

over the twelve coordinates ``x = (p, a, b, c)``, with the weights ``w_p = 1``,
``w_{s_0} = -(1 - sum_j theta_j)``, ``w_{s_j} = -theta_j`` (0 for a vertex off the feature). The
squared distance is the value ``d^2(x) = min_theta f`` (the point-point, point-edge and point-plane
distances of Incremental Potential Contact, Li et al. 2020, one formula for all three); where the
minimiser lies inside the feature it is smooth, with (the envelope theorem and its derivative)::

    grad_m d^2 = 2 w_m r
    Hess d^2  = f_xx - f_xt f_tt^-1 f_tx,   f_xx = 2 w w^T (x) I_3,   f_tt = 2 G,  G_jl = e_j . e_l,
    f_{x_m theta_j} = -2 (w_m e_j + r (delta_{m s_j} - delta_{m s_0})),   e_j = s_j - s_0

(``G`` the Gram matrix of the feature's edge vectors, 1 x 1 or 2 x 2). The feature is chosen by the
sign tests of Ericson's algorithm; on a boundary between two features both formulas give the same
value and gradient.
"""

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ..physics.base.jit import kernel


class PairScratch(NamedTuple):
    """Scratch of one point-triangle pair's derivatives."""

    pos: NDArray[np.float64]  # (4, 3) m: p, a, b, c
    w: NDArray[np.float64]  # (4,) the weights of r
    r: NDArray[np.float64]  # (3,) m
    e: NDArray[np.float64]  # (2, 3) m: the feature's edge vectors
    f: NDArray[np.float64]  # (12, 2) m: f_x theta
    feature: NDArray[np.int64]  # (4,): k + 1, then s_0..s_k (local indices 1..3)
    theta: NDArray[np.float64]  # (2,) the feature's parameters
    g: NDArray[np.float64]  # (12,) m: grad d^2
    h: NDArray[np.float64]  # (12, 12): Hess d^2, then the barrier's
    vecs: NDArray[np.float64]  # (12, 12) eigenvectors (projection.py)
    lam: NDArray[np.float64]  # (12,) eigenvalues


def make_scratch() -> PairScratch:
    """A zero ``PairScratch``."""
    z = np.zeros
    return PairScratch(
        z((4, 3)),
        z(4),
        z(3),
        z((2, 3)),
        z((12, 2)),
        np.zeros(4, dtype=np.int64),
        z(2),
        z(12),
        z((12, 12)),
        z((12, 12)),
        z(12),
    )


@kernel(inline="always")
def _dot(pos, i, j, k, l):
    """``(pos_i - pos_j) . (pos_k - pos_l)``."""
    s = 0.0
    for a in range(3):
        s += (pos[i, a] - pos[j, a]) * (pos[k, a] - pos[l, a])
    return s


@kernel(inline="always")
def _set(feature, theta, n, s0, s1, s2, t1, t2):
    feature[0], feature[1], feature[2], feature[3] = n, s0, s1, s2
    theta[0], theta[1] = t1, t2


@kernel
def closest_feature(pos, feature, theta):
    """The feature of the triangle ``pos[1:4]`` closest to ``pos[0]`` into ``feature`` (module doc:
    ``k + 1`` vertices, then their local indices) and its parameters into ``theta`` (2,)."""
    d1, d2 = _dot(pos, 2, 1, 0, 1), _dot(pos, 3, 1, 0, 1)
    if d1 <= 0.0 and d2 <= 0.0:
        return _set(feature, theta, 1, 1, 0, 0, 0.0, 0.0)
    d3, d4 = _dot(pos, 2, 1, 0, 2), _dot(pos, 3, 1, 0, 2)
    if d3 >= 0.0 and d4 <= d3:
        return _set(feature, theta, 1, 2, 0, 0, 0.0, 0.0)
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        return _set(feature, theta, 2, 1, 2, 0, d1 / (d1 - d3), 0.0)
    d5, d6 = _dot(pos, 2, 1, 0, 3), _dot(pos, 3, 1, 0, 3)
    if d6 >= 0.0 and d5 <= d6:
        return _set(feature, theta, 1, 3, 0, 0, 0.0, 0.0)
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        return _set(feature, theta, 2, 1, 3, 0, d2 / (d2 - d6), 0.0)
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and d4 - d3 >= 0.0 and d5 - d6 >= 0.0:
        return _set(feature, theta, 2, 2, 3, 0, (d4 - d3) / ((d4 - d3) + (d5 - d6)), 0.0)
    denom = 1.0 / (va + vb + vc)
    return _set(feature, theta, 3, 1, 2, 3, vb * denom, vc * denom)


@kernel
def _residual(sc, theta):
    """The weights ``w``, the edge vectors ``e`` and ``r = p - q`` of the feature; returns ``|r|^2``."""
    pos, feature, w = sc.pos, sc.feature, sc.w
    n = feature[0]
    w[0], w[1], w[2], w[3] = 1.0, 0.0, 0.0, 0.0
    w[feature[1]] = -1.0
    for j in range(1, n):
        w[feature[1]] += theta[j - 1]
        w[feature[j + 1]] = -theta[j - 1]
        for a in range(3):
            sc.e[j - 1, a] = pos[feature[j + 1], a] - pos[feature[1], a]
    d2 = 0.0
    for a in range(3):
        s = 0.0
        for m in range(4):
            s += w[m] * pos[m, a]
        sc.r[a] = s
        d2 += s * s
    return d2


@kernel
def gather(x, idx, pos):
    """The positions of the global vertices ``idx`` (4,) of ``x`` (N, 3) into ``pos`` (4, 3)."""
    for m in range(4):
        for a in range(3):
            pos[m, a] = x[idx[m], a]


@kernel
def distance2(sc):
    """The squared distance (m^2) from ``sc.pos[0]`` to the triangle ``sc.pos[1:4]``."""
    closest_feature(sc.pos, sc.feature, sc.theta)
    return _residual(sc, sc.theta)


@kernel
def _gram_inverse(e, n):
    """``(2 G)^-1`` of the feature's ``n - 1`` edge vectors, as ``(i00, i01, i11)``."""
    if n == 2:
        return 0.5 / (e[0, 0] ** 2 + e[0, 1] ** 2 + e[0, 2] ** 2), 0.0, 0.0
    g00 = e[0, 0] ** 2 + e[0, 1] ** 2 + e[0, 2] ** 2
    g11 = e[1, 0] ** 2 + e[1, 1] ** 2 + e[1, 2] ** 2
    g01 = e[0, 0] * e[1, 0] + e[0, 1] * e[1, 1] + e[0, 2] * e[1, 2]
    det = 2.0 * (g00 * g11 - g01 * g01)
    return g11 / det, -g01 / det, g00 / det


@kernel
def derivatives(sc):
    """The squared distance (m^2) from ``sc.pos[0]`` to the triangle ``sc.pos[1:4]``; its gradient
    (m) into ``sc.g`` (12,) and Hessian into ``sc.h`` (12, 12) (module doc)."""
    closest_feature(sc.pos, sc.feature, sc.theta)
    d2 = _residual(sc, sc.theta)
    w, r, f, feature = sc.w, sc.r, sc.f, sc.feature
    n = feature[0]
    for m in range(4):
        for a in range(3):
            sc.g[3 * m + a] = 2.0 * w[m] * r[a]
            for j in range(2):
                f[3 * m + a, j] = 0.0
            for j in range(n - 1):
                delta = (1.0 if m == feature[j + 2] else 0.0) - (1.0 if m == feature[1] else 0.0)
                f[3 * m + a, j] = -2.0 * (w[m] * sc.e[j, a] + r[a] * delta)
    i00, i01, i11 = _gram_inverse(sc.e, n) if n > 1 else (0.0, 0.0, 0.0)
    for p in range(12):
        for q in range(p, 12):
            v = 2.0 * w[p // 3] * w[q // 3] if p % 3 == q % 3 else 0.0
            v -= f[p, 0] * (i00 * f[q, 0] + i01 * f[q, 1]) + f[p, 1] * (i01 * f[q, 0] + i11 * f[q, 1])
            sc.h[p, q] = sc.h[q, p] = v
    return d2


def point_triangle(pos: NDArray[np.float64]) -> tuple[float, NDArray[np.float64], NDArray[np.float64], int]:
    """``(d^2 m^2, grad (12,), Hess (12, 12), vertices of the closest feature)`` of the point
    ``pos[0]`` and the triangle ``pos[1:4]`` (4, 3) m."""
    sc = make_scratch()
    sc.pos[:] = pos
    d2 = derivatives(sc)
    return float(d2), sc.g.copy(), sc.h.copy(), int(sc.feature[0])


def point_triangle_distance(pos: NDArray[np.float64]) -> float:
    """The distance (m) of the point ``pos[0]`` from the triangle ``pos[1:4]`` (4, 3) m."""
    sc = make_scratch()
    sc.pos[:] = pos
    return math.sqrt(float(distance2(sc)))
