"""The contact barrier between shells and within one: Incremental Potential Contact (Li et al.
2020) on point-triangle distances, and the continuous collision detection that keeps every straight
motion intersection-free.

A candidate pair (broadphase.py) of a vertex ``p`` and a triangle ``(a, b, c)`` at the distance
``d`` (m, distance.py) is held apart by the grounds' potential (ground.py)::

    B = kappa dhat^2 beta(d^2 / dhat^2),   beta(y) = -(y - 1)^2 ln y  (0 < y < 1; 0 for y >= 1)

(J; ``dhat`` = ``Scene.contact_distance``, ``kappa`` N/m the larger of the two shells'
``Scene.contact_stiffness`` or ``E h``), with, ``y = d^2 / dhat^2`` and ``g = grad d^2``::

    grad B = kappa beta'(y) g,   Hess B = kappa (beta''(y) / dhat^2 g g^T + beta'(y) Hess d^2)

projected to the nearest positive semi-definite matrix (projection.py) for Newton's matrix (the
distance's curvature enters with ``beta' < 0``). ``B`` is ``C^1`` in the positions where the
closest feature changes and ``C^2`` inside each feature's region; it grows without bound as
``d -> 0``, so no state of finite energy has a vertex on a triangle of another shell (or of its own,
with self-contact).

**Why point-triangle only.** Two closed triangle meshes intersect only if an edge of one crosses a
triangle of the other; a crossing without a vertex inside needs two edges to pass through each other
while every vertex stays outside, which between two convex, pressurised balls (whose contact
patches flatten face on face) would need the patch's edges to cross at a sharp angle without any
of their ends coming within ``dhat``. The edge-edge barrier (with its mollifier for parallel edges)
is left out; the tests check that no edge of one ball crosses a triangle of the other.

**Friction** between shells is not modelled: the contact is frictionless.

**Continuous collision detection** (:func:`max_step`): along a straight motion ``x + alpha dx`` a
pair's distance changes at most at the rate ``l = |dp - m| + max_j |dt_j - m|`` (``m`` the mean of
the four motions: a common translation changes nothing), so it stays above ``(1 - CCD_SAFETY) d_0``
for ``alpha`` up to ``(d - (1 - CCD_SAFETY) d_0) / l``; advancing by that bound and evaluating the
distance again (additive CCD, Li et al. 2021) gives the largest such ``alpha`` a pair allows, the
smallest over the candidates caps the step, as ``ground.max_step`` does for the grounds.
"""

import math

from ..physics.base.jit import kernel
from ..physics.walls.self_barrier import beta, beta_curvature, beta_slope
from .distance import derivatives, distance2, gather
from .projection import project_psd

CCD_SAFETY = 0.8  # a pair's distance may fall to 1 - CCD_SAFETY of its start along a motion
CCD_ITERATIONS = 200  # additive CCD's advances per pair and motion, at most
CCD_STALL = 1e-4  # an advance below this fraction of the motion ends the search


@kernel(inline="always")
def pair_stiffness(kappa, idx, n_vertices):
    """``kappa`` (N/m) of a pair: the larger of its two shells'."""
    return max(kappa[idx[0] // n_vertices], kappa[idx[1] // n_vertices])


@kernel
def energy(pairs, count, x, kappa, dhat, sc):
    """``sum B`` (J) over the candidate pairs ``pairs[:count]`` at ``x`` (S V, 3) m; inf if a pair
    touches. ``kappa`` (S,) N/m per shell, ``sc`` a ``distance.PairScratch``."""
    total = 0.0
    n_vertices = x.shape[0] // kappa.shape[0]
    reach = dhat * dhat
    for p in range(count):
        gather(x, pairs[p], sc.pos)
        d2 = distance2(sc)
        if d2 < reach:
            if not d2 > 0.0:
                return math.inf
            total += pair_stiffness(kappa, pairs[p], n_vertices) * reach * beta(d2 / reach)
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
def add_barrier(pairs, count, x, kappa, dhat, grad, blocks, active, hess, sc, hessian):
    """Adds ``grad B`` (N) to ``grad`` (S V, 3); with ``hessian``, each touching pair's projected
    ``Hess B`` (N/m): its vertices' diagonal 3 x 3 blocks to ``blocks`` (S V, 3, 3), the whole
    (12, 12) matrix to ``hess`` and the pair's vertices to ``active`` (A, 4). Returns the touching
    pairs, -1 if more than ``active`` holds (with ``hessian``)."""
    n_vertices = x.shape[0] // kappa.shape[0]
    reach = dhat * dhat
    touching = 0
    for p in range(count):
        idx = pairs[p]
        gather(x, idx, sc.pos)
        d2 = derivatives(sc)
        if not (0.0 < d2 < reach):
            continue
        y = d2 / reach
        k = pair_stiffness(kappa, idx, n_vertices)
        slope = k * beta_slope(y)
        for m in range(4):
            for a in range(3):
                grad[idx[m], a] += slope * sc.g[3 * m + a]
        if hessian:
            if touching == active.shape[0]:
                return -1
            _barrier_hessian(sc, k, y, dhat)
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
    """``l`` (m per unit alpha) of the module doc."""
    mean0 = mean1 = mean2 = 0.0
    for m in range(4):
        mean0 += 0.25 * dx[idx[m], 0]
        mean1 += 0.25 * dx[idx[m], 1]
        mean2 += 0.25 * dx[idx[m], 2]
    point = triangle = 0.0
    for m in range(4):
        u = dx[idx[m], 0] - mean0
        v = dx[idx[m], 1] - mean1
        w = dx[idx[m], 2] - mean2
        n = math.sqrt(u * u + v * v + w * w)
        if m == 0:
            point = n
        else:
            triangle = max(triangle, n)
    return point + triangle


@kernel
def _pair_step(x, dx, idx, cap, sc):
    """The largest ``alpha <= cap`` additive CCD allows the pair ``idx`` (module doc)."""
    rate = _motion_bound(dx, idx)
    if rate <= 0.0:
        return cap
    gather(x, idx, sc.pos)
    floor = (1.0 - CCD_SAFETY) * math.sqrt(distance2(sc))
    alpha = 0.0
    for _ in range(CCD_ITERATIONS):
        for m in range(4):
            for a in range(3):
                sc.pos[m, a] = x[idx[m], a] + alpha * dx[idx[m], a]
        advance = (math.sqrt(distance2(sc)) - floor) / rate
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
        low = min(low, distance2(sc))
    return math.sqrt(low)
