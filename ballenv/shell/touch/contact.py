"""The contact barrier between shells and within one: Incremental Potential Contact (Li et al.
2020) on point-triangle and edge-edge distances, and the continuous collision detection that keeps
every straight motion intersection-free.

A candidate pair (broadphase.py) of a vertex and a triangle, or of two edges, at the distance ``d``
(m, distance.py) is held apart by the grounds' potential (ground.py)::

    B = kappa dhat^2 beta(d^2 / dhat^2),   beta(y) = -(y - 1)^2 ln y  (0 < y < 1; 0 for y >= 1)

(J; ``dhat`` = ``Scene.contact_distance``, ``kappa`` N/m the larger of the two shells'
``Scene.contact_stiffness`` or ``E h``), with, ``y = d^2 / dhat^2`` and ``g = grad d^2``::

    grad B = kappa beta'(y) g,   Hess B = kappa (beta''(y) / dhat^2 g g^T + beta'(y) Hess d^2)

An edge-edge pair's is mollified as in Incremental Potential Contact, ``m(c) B`` with ``c = |e_1 x
e_2|^2`` (m^4), ``m = (2 - c / eps) c / eps`` below ``eps = EDGE_MOLLIFIER |e_1|^2 |e_2|^2`` (rest
lengths) and 1 above, so that it vanishes smoothly as the edges turn parallel (where their
distance's Hessian is singular and the point-triangle pairs of their ends take over). Each pair's
matrix is projected to the nearest positive semi-definite one (projection.py; in the span of ``w (x)
e_a`` and ``f_x theta`` of distance.py, at most five dimensions, which holds ``g`` and ``Hess d^2``,
unless mollified) for Newton's matrix (the distance's curvature enters with ``beta' < 0``). ``B`` is
``C^1`` where the closest features change and ``C^2`` elsewhere; it grows without bound as ``d ->
0``, so no state of finite energy has a vertex on a triangle or an edge on an edge of another shell
(or of its own, with self-contact).

**Why both kinds.** Two closed triangle meshes intersect only if an edge of one crosses a triangle
of the other. Between two balls pressed face to face the point-triangle pairs hold every vertex
outside the other ball, but at high speed (the tests' 20 m/s collision) ridges of the two meshes
cross while all their ends stay outside: the edge-edge pairs and their continuous collision
detection exclude that.

**Friction** between shells is not modelled: the contact is frictionless.

**Continuous collision detection** (:func:`max_step`): along a straight motion ``x + alpha dx`` a
pair's distance changes at most at the rate ``l = max_i |dx_i - m| + max_j |dx_j - m|`` over its two
sides' vertices (``m`` the mean of the four motions: a common translation changes nothing), so it
stays above ``(1 - CCD_SAFETY) d_0`` for ``alpha`` up to ``(d - (1 - CCD_SAFETY) d_0) / l``;
advancing by that bound and evaluating the distance again (additive CCD, Li et al. 2021) gives the
largest such ``alpha`` a pair allows; the smallest over the candidates caps the step, as
``ground.max_step`` does for the grounds.
"""

import math

import numpy as np
from numpy.typing import NDArray

from ...physics.base.jit import kernel
from ...physics.walls.self_barrier import beta, beta_curvature, beta_slope
from .distance import EDGE_EDGE, cross_derivatives, derivatives, distance2, gather, make_scratch, range_basis
from .projection import project_psd, project_psd_in

EDGE_MOLLIFIER = 1e-3  # eps of the edge-edge mollifier against the rest edges' |e_1|^2 |e_2|^2
CCD_SAFETY = 0.8  # a pair's distance may fall to 1 - CCD_SAFETY of its start along a motion
CCD_ITERATIONS = 200  # additive CCD's advances per pair and motion, at most
CCD_STALL = 1e-4  # an advance below this fraction of the motion ends the search


@kernel(inline="always")
def pair_stiffness(kappa, idx, n_vertices):
    """``kappa`` (N/m) of a pair: the larger of its two shells'."""
    return max(kappa[idx[0] // n_vertices], kappa[idx[1] // n_vertices])


@kernel
def _mollifier_scale(rest, idx):
    """``eps`` (m^4) of an edge-edge pair (module doc), from the rest positions (S V, 3)."""
    a = b = 0.0
    for c in range(3):
        a += (rest[idx[1], c] - rest[idx[0], c]) ** 2
        b += (rest[idx[3], c] - rest[idx[2], c]) ** 2
    return EDGE_MOLLIFIER * a * b


@kernel
def _cross(pos):
    """``|e_1 x e_2|^2`` (m^4) of the edges ``pos[0] pos[1]`` and ``pos[2] pos[3]``."""
    u0, u1, u2 = pos[1, 0] - pos[0, 0], pos[1, 1] - pos[0, 1], pos[1, 2] - pos[0, 2]
    v0, v1, v2 = pos[3, 0] - pos[2, 0], pos[3, 1] - pos[2, 1], pos[3, 2] - pos[2, 2]
    return (u1 * v2 - u2 * v1) ** 2 + (u2 * v0 - u0 * v2) ** 2 + (u0 * v1 - u1 * v0) ** 2


@kernel
def energy(pairs, count, x, rest, kappa, dhat, sc):
    """``sum B`` (J) over the candidate pairs ``pairs[:count]`` at ``x`` (S V, 3) m (``rest`` their
    rest positions); inf if a pair touches. ``kappa`` (S,) N/m per shell, ``sc`` a
    ``distance.PairScratch``."""
    total = 0.0
    n_vertices = x.shape[0] // kappa.shape[0]
    reach = dhat * dhat
    for p in range(count):
        gather(x, pairs[p], sc.pos)
        d2 = distance2(sc, pairs[p, 4])
        if d2 < reach:
            if not d2 > 0.0:
                return math.inf
            b = pair_stiffness(kappa, pairs[p], n_vertices) * reach * beta(d2 / reach)
            if pairs[p, 4] == EDGE_EDGE:
                eps = _mollifier_scale(rest, pairs[p])
                q = min(_cross(sc.pos) / eps, 1.0)
                b *= (2.0 - q) * q
            total += b
    return total


@kernel
def _barrier_hessian(sc, k, y, dhat):
    """``Hess B`` (N/m) from ``Hess d^2`` in ``sc.h``, in place, projected (module doc)."""
    c1 = k * beta_curvature(y) / (dhat * dhat)
    c2 = k * beta_slope(y)
    for p in range(12):
        for q in range(12):
            sc.h[p, q] = c1 * sc.g[p] * sc.g[q] + c2 * sc.h[p, q]
    project_psd(sc.h, sc.vecs, sc.lam)


@kernel
def _mollify(sc, b, eps):
    """``m(c) B`` of an edge-edge pair: its gradient into ``sc.g`` and Hessian into ``sc.h``, from
    ``B`` (J), ``grad B`` and ``Hess B`` there (module doc); False (nothing changed) where
    ``m = 1``."""
    c = cross_derivatives(sc)
    if c >= eps:
        return False
    q = c / eps
    m, dm, ddm = (2.0 - q) * q, (2.0 - 2.0 * q) / eps, -2.0 / (eps * eps)
    for p in range(12):
        for r in range(12):
            sc.h[p, r] = (
                m * sc.h[p, r] + b * (ddm * sc.gc[p] * sc.gc[r] + dm * sc.hc[p, r])
                + dm * (sc.gc[p] * sc.g[r] + sc.g[p] * sc.gc[r])
            )  # fmt: skip
    for p in range(12):
        sc.g[p] = m * sc.g[p] + b * dm * sc.gc[p]
    return True


@kernel
def _pair(sc, pair, rest, k, dhat, hessian):
    """``B`` (J) of the pair at ``sc.pos`` (its kind ``pair[4]``), its gradient (N) into ``sc.g``
    and, with ``hessian``, its projected Hessian (N/m) into ``sc.h``; 0 beyond ``dhat``."""
    reach = dhat * dhat
    d2 = derivatives(sc, pair[4])
    if not (0.0 < d2 < reach):
        return 0.0
    y = d2 / reach
    c1, c2 = k * beta_curvature(y) / reach, k * beta_slope(y)
    for p in range(12):
        for q in range(12):
            sc.h[p, q] = c1 * sc.g[p] * sc.g[q] + c2 * sc.h[p, q]
    for p in range(12):
        sc.g[p] *= c2
    b = k * reach * beta(y)
    mollified = pair[4] == EDGE_EDGE and _mollify(sc, b, _mollifier_scale(rest, pair))
    if hessian and mollified:
        project_psd(sc.h, sc.vecs, sc.lam)
    elif hessian:
        range_basis(sc)
        project_psd_in(sc.h, sc.basis, sc.small, sc.small_vecs, sc.lam)
    return b


@kernel
def add_barrier(pairs, count, x, rest, kappa, dhat, grad, blocks, active, hess, sc, hessian):
    """Adds ``grad B`` (N) to ``grad`` (S V, 3); with ``hessian``, each touching pair's projected
    ``Hess B`` (N/m): its vertices' diagonal 3 x 3 blocks to ``blocks`` (S V, 3, 3), the whole
    (12, 12) matrix to ``hess`` and the pair's vertices to ``active`` (A, 4). Returns the touching
    pairs, -1 if more than ``active`` holds (with ``hessian``)."""
    n_vertices = x.shape[0] // kappa.shape[0]
    touching = 0
    for p in range(count):
        idx = pairs[p]
        gather(x, idx, sc.pos)
        if _pair(sc, idx, rest, pair_stiffness(kappa, idx, n_vertices), dhat, hessian) == 0.0:
            continue
        for m in range(4):
            for a in range(3):
                grad[idx[m], a] += sc.g[3 * m + a]
        if hessian:
            if touching == active.shape[0]:
                return -1
            _store(sc.h, idx, blocks, active[touching], hess[touching])
        touching += 1
    return touching


@kernel
def _store(h, idx, blocks, active_row, hess_row):
    for m in range(4):
        active_row[m] = idx[m]
        for a in range(3):
            for b in range(3):
                blocks[idx[m], a, b] += h[3 * m + a, 3 * m + b]
    for p in range(12):
        for q in range(12):
            hess_row[p, q] = h[p, q]


@kernel
def _motion_bound(dx, idx):
    """``l`` (m per unit alpha) of the module doc (the sides: ``idx[:1]``, ``idx[1:4]`` for a
    point-triangle pair, ``idx[:2]``, ``idx[2:4]`` for an edge-edge pair)."""
    mean0 = mean1 = mean2 = 0.0
    for m in range(4):
        mean0 += 0.25 * dx[idx[m], 0]
        mean1 += 0.25 * dx[idx[m], 1]
        mean2 += 0.25 * dx[idx[m], 2]
    first = second = 0.0
    split = 2 if idx[4] == EDGE_EDGE else 1
    for m in range(4):
        u = dx[idx[m], 0] - mean0
        v = dx[idx[m], 1] - mean1
        w = dx[idx[m], 2] - mean2
        n = math.sqrt(u * u + v * v + w * w)
        if m < split:
            first = max(first, n)
        else:
            second = max(second, n)
    return first + second


@kernel
def _pair_step(x, dx, idx, cap, sc):
    """The largest ``alpha <= cap`` additive CCD allows the pair ``idx`` (module doc)."""
    rate = _motion_bound(dx, idx)
    if rate <= 0.0:
        return cap
    gather(x, idx, sc.pos)
    floor = (1.0 - CCD_SAFETY) * math.sqrt(distance2(sc, idx[4]))
    alpha = 0.0
    for _ in range(CCD_ITERATIONS):
        for m in range(4):
            for a in range(3):
                sc.pos[m, a] = x[idx[m], a] + alpha * dx[idx[m], a]
        advance = (math.sqrt(distance2(sc, idx[4])) - floor) / rate
        if alpha + advance >= cap:
            return cap
        if advance <= CCD_STALL * cap:
            return alpha
        alpha += advance
    return alpha


@kernel
def max_step(pairs, count, x, dx, cap, sc):
    """The largest ``alpha <= cap`` for which ``x + alpha dx`` keeps every candidate pair at least
    ``1 - CCD_SAFETY`` of its distance apart (module doc)."""
    alpha = cap
    for p in range(count):
        alpha = _pair_step(x, dx, pairs[p], alpha, sc)
    return alpha


@kernel
def min_distance(pairs, count, x, sc):
    """The smallest distance (m) of a candidate pair at ``x`` (inf without pairs)."""
    low = math.inf
    for p in range(count):
        gather(x, pairs[p], sc.pos)
        low = min(low, distance2(sc, pairs[p, 4]))
    return math.sqrt(low)


def pair_barrier(
    pos: NDArray[np.float64], kind: int, kappa: float, dhat: float, rest: NDArray[np.float64], project: bool
) -> tuple[float, NDArray[np.float64], NDArray[np.float64]]:
    """``(B J, grad B (12,) N, Hess B (12, 12) N/m)`` of one pair of ``kind`` at ``pos`` (4, 3) m
    (rest positions ``rest`` (4, 3) m, for the edge-edge mollifier), projected if ``project``."""
    sc = make_scratch()
    sc.pos[:] = pos
    idx = np.array([0, 1, 2, 3, kind], dtype=np.int64)
    b = float(_pair(sc, idx, np.ascontiguousarray(rest, dtype=np.float64), kappa, dhat, project))
    if b > 0.0 and kind == EDGE_EDGE:
        q = min(float(_cross(sc.pos)) / float(_mollifier_scale(rest, idx)), 1.0)
        b *= (2.0 - q) * q
    return b, sc.g.copy(), sc.h.copy()
