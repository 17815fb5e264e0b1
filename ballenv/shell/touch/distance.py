"""The distance between a point and a triangle, and between two edges, in 3-D, with their exact
gradients and Hessians.

Both are the smallest ``|r|`` of a difference ``r = sum_m w_m(theta) x_m`` (m) over four vertices
``x = (x_0, ..., x_3)`` and up to two parameters ``theta``:

* **point-triangle** (``x_0`` the point, ``x_1..x_3`` the triangle): ``r = p - q``, ``q`` on the
  triangle's closest feature (Ericson, *Real-Time Collision Detection*, 5.1.5), a vertex, an edge
  ``s_0 + theta (s_1 - s_0)`` or the face ``s_0 + theta_1 (s_1 - s_0) + theta_2 (s_2 - s_0)``;
* **edge-edge** (``x_0 x_1`` and ``x_2 x_3``): ``r = x_0 + s (x_1 - x_0) - x_2 - t (x_3 - x_2)``
  with ``s, t`` clamped to [0, 1] (Ericson 5.1.9); those strictly inside are the parameters.

(the point-point, point-edge, point-plane and edge-line distances of Incremental Potential Contact,
Li et al. 2020, as one formula). With ``f(x, theta) = |r|^2`` and ``dr / dtheta_j = sigma_j (x_P_j -
x_M_j) = u_j`` the squared distance is the value ``d^2(x) = min_theta f``; where the minimiser is
inside its feature (the envelope theorem and its derivative)::

    grad_m d^2 = 2 w_m r
    Hess d^2  = f_xx - f_xt f_tt^-1 f_tx,   f_xx = 2 w w^T (x) I_3,   f_tt = 2 G,  G_jl = u_j . u_l,
    f_{x_m theta_j} = 2 (w_m u_j + sigma_j r (delta_{m P_j} - delta_{m M_j}))

(``G`` 1 x 1 or 2 x 2). On a boundary between two features both give the same value and gradient.
Two edges that are nearly parallel have a nearly singular ``G``; the barrier (contact.py) mollifies
their pair as Incremental Potential Contact does, with :func:`cross_derivatives`.
"""

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ...physics.base.jit import kernel

POINT_TRIANGLE, EDGE_EDGE = 0, 1  # the kinds of pair
RANGE_TOL = 1e-9  # a direction of f_x theta left after orthogonalisation below this share is dropped


class PairScratch(NamedTuple):
    """Scratch of one pair's derivatives."""

    pos: NDArray[np.float64]  # (4, 3) m
    w: NDArray[np.float64]  # (4,) the weights of r
    r: NDArray[np.float64]  # (3,) m
    u: NDArray[np.float64]  # (2, 3) m: dr / dtheta_j
    f: NDArray[np.float64]  # (12, 2) m: f_x theta
    feature: NDArray[np.int64]  # (5,): the parameters K, then P_0, M_0, P_1, M_1
    sign: NDArray[np.float64]  # (2,) sigma_j
    theta: NDArray[np.float64]  # (2,) the parameters
    g: NDArray[np.float64]  # (12,) m: grad d^2
    h: NDArray[np.float64]  # (12, 12): Hess d^2, then the barrier's
    gc: NDArray[np.float64]  # (12,) m^3: grad |e_1 x e_2|^2 (edge-edge)
    hc: NDArray[np.float64]  # (12, 12) m^2: its Hessian
    vecs: NDArray[np.float64]  # (12, 12) eigenvectors (projection.py)
    lam: NDArray[np.float64]  # (12,) eigenvalues
    basis: NDArray[np.float64]  # (5, 12) an orthonormal basis of Hess d^2's range (range_basis)
    small: NDArray[np.float64]  # (5, 5)
    small_vecs: NDArray[np.float64]  # (5, 5)


def make_scratch() -> PairScratch:
    """A zero ``PairScratch``."""
    z = np.zeros
    return PairScratch(
        z((4, 3)), z(4), z(3), z((2, 3)), z((12, 2)), np.zeros(5, dtype=np.int64), z(2), z(2), z(12),
        z((12, 12)), z(12), z((12, 12)), z((12, 12)), z(12), z((5, 12)), z((5, 5)), z((5, 5)),
    )  # fmt: skip


@kernel(inline="always")
def _dot(pos, i, j, k, l):
    """``(pos_i - pos_j) . (pos_k - pos_l)``."""
    s = 0.0
    for a in range(3):
        s += (pos[i, a] - pos[j, a]) * (pos[k, a] - pos[l, a])
    return s


@kernel
def _simplex(sc, n, s0, s1, s2, t1, t2):
    """The point-triangle difference of a feature of ``n`` vertices ``s0, s1, s2`` (module doc)."""
    w, f = sc.w, sc.feature
    w[0], w[1], w[2], w[3] = 1.0, 0.0, 0.0, 0.0
    w[s0] = -(1.0 - t1 - t2)
    f[0] = n - 1
    if n > 1:
        w[s1] = -t1
        f[1], f[2], sc.sign[0], sc.theta[0] = s1, s0, -1.0, t1
    if n > 2:
        w[s2] = -t2
        f[3], f[4], sc.sign[1], sc.theta[1] = s2, s0, -1.0, t2


@kernel
def _point_triangle(sc):
    """The closest feature of the triangle ``pos[1:4]`` to ``pos[0]`` (Ericson's region tests)."""
    pos = sc.pos
    d1, d2 = _dot(pos, 2, 1, 0, 1), _dot(pos, 3, 1, 0, 1)
    if d1 <= 0.0 and d2 <= 0.0:
        return _simplex(sc, 1, 1, 0, 0, 0.0, 0.0)
    d3, d4 = _dot(pos, 2, 1, 0, 2), _dot(pos, 3, 1, 0, 2)
    if d3 >= 0.0 and d4 <= d3:
        return _simplex(sc, 1, 2, 0, 0, 0.0, 0.0)
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        return _simplex(sc, 2, 1, 2, 0, d1 / (d1 - d3), 0.0)
    d5, d6 = _dot(pos, 2, 1, 0, 3), _dot(pos, 3, 1, 0, 3)
    if d6 >= 0.0 and d5 <= d6:
        return _simplex(sc, 1, 3, 0, 0, 0.0, 0.0)
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        return _simplex(sc, 2, 1, 3, 0, d2 / (d2 - d6), 0.0)
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and d4 - d3 >= 0.0 and d5 - d6 >= 0.0:
        return _simplex(sc, 2, 2, 3, 0, (d4 - d3) / ((d4 - d3) + (d5 - d6)), 0.0)
    denom = 1.0 / (va + vb + vc)
    return _simplex(sc, 3, 1, 2, 3, vb * denom, vc * denom)


@kernel
def _edge_edge(sc):
    """The closest points of the segments ``pos[0] pos[1]`` and ``pos[2] pos[3]`` (Ericson 5.1.9)."""
    pos = sc.pos
    a, e, b = _dot(pos, 1, 0, 1, 0), _dot(pos, 3, 2, 3, 2), _dot(pos, 1, 0, 3, 2)
    c, f = _dot(pos, 1, 0, 0, 2), _dot(pos, 3, 2, 0, 2)
    denom = a * e - b * b
    s = min(max((b * f - c * e) / denom, 0.0), 1.0) if denom > 0.0 else 0.0
    t = (b * s + f) / e
    if t < 0.0:
        t, s = 0.0, min(max(-c / a, 0.0), 1.0)
    elif t > 1.0:
        t, s = 1.0, min(max((b - c) / a, 0.0), 1.0)
    w, feature = sc.w, sc.feature
    w[0], w[1], w[2], w[3] = 1.0 - s, s, t - 1.0, -t
    k = 0
    if 0.0 < s < 1.0:
        feature[1], feature[2], sc.sign[0], sc.theta[0] = 1, 0, 1.0, s
        k = 1
    if 0.0 < t < 1.0:
        feature[1 + 2 * k], feature[2 + 2 * k], sc.sign[k], sc.theta[k] = 3, 2, -1.0, t
        k += 1
    feature[0] = k


@kernel
def _residual(sc):
    """``u_j`` and ``r`` of the feature found; returns ``|r|^2``."""
    pos, feature = sc.pos, sc.feature
    for j in range(feature[0]):
        for a in range(3):
            sc.u[j, a] = sc.sign[j] * (pos[feature[1 + 2 * j], a] - pos[feature[2 + 2 * j], a])
    d2 = 0.0
    for a in range(3):
        s = 0.0
        for m in range(4):
            s += sc.w[m] * pos[m, a]
        sc.r[a] = s
        d2 += s * s
    return d2


@kernel
def gather(x, idx, pos):
    """The positions of the global vertices ``idx[:4]`` of ``x`` (N, 3) into ``pos`` (4, 3)."""
    for m in range(4):
        for a in range(3):
            pos[m, a] = x[idx[m], a]


@kernel
def distance2(sc, kind):
    """The squared distance (m^2) of the pair ``kind`` at ``sc.pos`` (module doc)."""
    if kind == POINT_TRIANGLE:
        _point_triangle(sc)
    else:
        _edge_edge(sc)
    return _residual(sc)


@kernel
def _gram_inverse(u, k):
    """``(2 G)^-1`` of ``k`` vectors ``u``, as ``(i00, i01, i11)``."""
    g00 = u[0, 0] ** 2 + u[0, 1] ** 2 + u[0, 2] ** 2
    if k == 1:
        return 0.5 / g00, 0.0, 0.0
    g11 = u[1, 0] ** 2 + u[1, 1] ** 2 + u[1, 2] ** 2
    g01 = u[0, 0] * u[1, 0] + u[0, 1] * u[1, 1] + u[0, 2] * u[1, 2]
    det = 2.0 * (g00 * g11 - g01 * g01)
    return g11 / det, -g01 / det, g00 / det


@kernel
def derivatives(sc, kind):
    """The squared distance (m^2) of the pair ``kind`` at ``sc.pos``; its gradient (m) into ``sc.g``
    (12,) and Hessian into ``sc.h`` (12, 12) (module doc)."""
    d2 = distance2(sc, kind)
    w, r, f, feature = sc.w, sc.r, sc.f, sc.feature
    k = feature[0]
    for m in range(4):
        for a in range(3):
            sc.g[3 * m + a] = 2.0 * w[m] * r[a]
            f[3 * m + a, 0] = f[3 * m + a, 1] = 0.0
            for j in range(k):
                delta = (1.0 if m == feature[1 + 2 * j] else 0.0) - (1.0 if m == feature[2 + 2 * j] else 0.0)
                f[3 * m + a, j] = 2.0 * (w[m] * sc.u[j, a] + sc.sign[j] * r[a] * delta)
    i00, i01, i11 = _gram_inverse(sc.u, k) if k > 0 else (0.0, 0.0, 0.0)
    for p in range(12):
        for q in range(p, 12):
            v = 2.0 * w[p // 3] * w[q // 3] if p % 3 == q % 3 else 0.0
            v -= f[p, 0] * (i00 * f[q, 0] + i01 * f[q, 1]) + f[p, 1] * (i01 * f[q, 0] + i11 * f[q, 1])
            sc.h[p, q] = sc.h[q, p] = v
    return d2


@kernel
def range_basis(sc):
    """An orthonormal basis (rows, zero rows where the span is smaller) of the span of ``w (x) e_a``
    (a = 1, 2, 3) and the columns of ``f_x theta`` into ``sc.basis`` (5, 12): it holds the range of
    ``Hess d^2`` and ``grad d^2`` (module doc), after :func:`derivatives`."""
    b, w, k = sc.basis, sc.w, sc.feature[0]
    b[:] = 0.0
    norm = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2] + w[3] * w[3])
    for a in range(3):
        for m in range(4):
            b[a, 3 * m + a] = w[m] / norm
    for j in range(k):
        row = 3 + j
        size = 0.0
        for p in range(12):
            b[row, p] = sc.f[p, j]
            size += sc.f[p, j] * sc.f[p, j]
        for i in range(row):
            dot = 0.0
            for p in range(12):
                dot += b[i, p] * b[row, p]
            for p in range(12):
                b[row, p] -= dot * b[i, p]
        left = 0.0
        for p in range(12):
            left += b[row, p] * b[row, p]
        scale = 1.0 / math.sqrt(left) if left > RANGE_TOL * RANGE_TOL * size else 0.0
        for p in range(12):
            b[row, p] *= scale


@kernel
def cross_derivatives(sc):
    """``c = |e_1 x e_2|^2 = |e_1|^2 |e_2|^2 - (e_1 . e_2)^2`` (m^4) of the edges
    ``e_1 = pos[1] - pos[0]``, ``e_2 = pos[3] - pos[2]``; its gradient into ``sc.gc`` (12,) and
    Hessian into ``sc.hc`` (12, 12)."""
    pos = sc.pos
    uu, vv, uv = _dot(pos, 1, 0, 1, 0), _dot(pos, 3, 2, 3, 2), _dot(pos, 1, 0, 3, 2)
    sc.hc[:] = 0.0
    for a in range(3):
        u_a, v_a = pos[1, a] - pos[0, a], pos[3, a] - pos[2, a]
        gu, gv = 2.0 * vv * u_a - 2.0 * uv * v_a, 2.0 * uu * v_a - 2.0 * uv * u_a
        sc.gc[a], sc.gc[3 + a], sc.gc[6 + a], sc.gc[9 + a] = -gu, gu, -gv, gv
        for b in range(3):
            u_b, v_b = pos[1, b] - pos[0, b], pos[3, b] - pos[2, b]
            eye = 1.0 if a == b else 0.0
            huu = 2.0 * vv * eye - 2.0 * v_a * v_b
            hvv = 2.0 * uu * eye - 2.0 * u_a * u_b
            huv = 4.0 * u_a * v_b - 2.0 * v_a * u_b - 2.0 * uv * eye
            for m, sm in ((0, -1.0), (1, 1.0)):
                for q, sq in ((0, -1.0), (1, 1.0)):
                    sc.hc[3 * m + a, 3 * q + b] = sm * sq * huu
                    sc.hc[6 + 3 * m + a, 6 + 3 * q + b] = sm * sq * hvv
                    sc.hc[3 * m + a, 6 + 3 * q + b] = sm * sq * huv
                    sc.hc[6 + 3 * q + b, 3 * m + a] = sm * sq * huv
    return uu * vv - uv * uv


def pair_derivatives(
    pos: NDArray[np.float64], kind: int
) -> tuple[float, NDArray[np.float64], NDArray[np.float64], int]:
    """``(d^2 m^2, grad (12,), Hess (12, 12), the feature's parameters)`` of the pair ``kind`` at
    ``pos`` (4, 3) m."""
    sc = make_scratch()
    sc.pos[:] = pos
    d2 = derivatives(sc, kind)
    return float(d2), sc.g.copy(), sc.h.copy(), int(sc.feature[0])


def pair_distance(pos: NDArray[np.float64], kind: int) -> float:
    """The distance (m) of the pair ``kind`` at ``pos`` (4, 3) m."""
    sc = make_scratch()
    sc.pos[:] = pos
    return math.sqrt(float(distance2(sc, kind)))
