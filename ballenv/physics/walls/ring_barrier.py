"""Contact between rings: the barrier potential of a node of one ring and an edge of another.

With the self-contact barrier (``Scene.self_intersection = "barrier"``) and two or more colliding
rings, a node ``p`` of ring ``a`` and an edge ``(j, j + 1)`` of ring ``b != a`` repel through the
potential of Incremental Potential Contact (Li et al., ACM TOG 2020) on their distance ``d`` (m)::

    E = kappa dhat^2 beta(d^2 / dhat^2),   beta(y) = -(y - 1)^2 ln y   (0 < y < 1; 0 for y >= 1)

with the contact distance ``dhat = h_a + h_b`` (m; the sum of the wall thicknesses, "twice the
thickness" for equal rings: the distance at which the explicit collision impulses act) and
``kappa = max(min(EA_a / l_a, EA_b / l_b), (K_a + K_b) / (dhat^2 beta(STOP_GAP^2)))`` (N/m: the
axial stiffness of one edge of the softer ring or, if larger, the stiffness that spends the two
rings' kinetic energies at the start before they come closer than ``STOP_GAP dhat``; the self
barrier's choice for one ring, :func:`walls.self_barrier.stiffness`). ``E`` (J) is ``C^2``, zero with its
first two derivatives at ``d = dhat``, infinite at ``d = 0``: a conservative potential, part of the scene's
energy. Its force and exact Hessian are those of :mod:`ballenv.physics.walls.self_barrier`
(``point_edge_derivatives``).

**Pairs.** Broad phase on the rings' boxes swept over a motion ``xa -> xb`` and grown by their
thickness (the sort and sweep of :func:`walls.broad_phase.overlapping_pairs`); for each pair of rings, the
nodes of one and the edges of the other whose swept boxes lie within ``dhat`` of the other ring's
box are listed in O(N), and only those are tested against each other (their boxes within
``dhat``). Rows of ``RingContactWorkspace.pairs``: ``(a, i, b, j)``.

**Structure.** A pair's Hessian couples node ``i`` of ring ``a`` with nodes ``j, j + 1`` of ring
``b``. The blocks within one ring (``(i, i)``; ``(j, j)``, ``(j, j+1)``, ...) go into that ring's
band; the blocks between rings are the rows of the coupled nodes: node ``k``'s row is the two
columns ``e_{2k+d} w_{k,d}^T`` (``e`` a unit column of its ring, ``w`` its entries in the other
rings' unknowns), stored as a list of entries (:mod:`ballenv.physics.step.joint_newton` solves the joint
system).

**Continuous detection.** :func:`impact_fraction` is the first time (fraction of a straight motion
of every node) a node of one ring meets an edge of another (:func:`walls.self_barrier.point_edge_impact`).
"""

import math
from typing import TYPE_CHECKING

from ..base.cyclic import next_node
from ..base.jit import kernel
from ..base.linalg import band_add_block
from .broad_phase import overlapping_pairs
from .self_barrier import (
    BETA_AT_STOP_GAP,
    beta,
    beta_curvature,
    beta_slope,
    point_edge_derivatives,
    point_edge_distance2,
    point_edge_impact,
)

if TYPE_CHECKING:
    from ..model import Model

PAIR_COLUMNS = 4  # a pair's row: ring a, node i of a, ring b, edge j of b (nodes j, j + 1)
PAIRS_PER_NODE = 8  # least room for candidate pairs per node of the scene (pairs_per_node)
ENTRIES_PER_PAIR = 16  # off-ring Hessian entries a pair adds: 8 in node i's rows, 4 in each edge end's


def pairs_per_node(model: "Model") -> int:
    """Room for candidate pairs per node of a scene (``Model``): a node within ``dhat`` of another
    ring's wall of edges ``l_0`` long faces up to ``2 dhat / l_0 + 2`` of them; twice that (two
    walls, or a node near a corner) plus slack, at least ``PAIRS_PER_NODE``. Walls thick against
    their edges (``dhat`` = 21 edges: N = 256 rings with h = 68 mm) need more than the default."""
    reach = 2.0 * float(model.thickness.max())
    edge = float(model.rest_len.min())
    return max(PAIRS_PER_NODE, 2 * math.ceil(2.0 * reach / edge) + 4)


@kernel(inline="always")
def pair_stiffness(model, a, b):
    """``kappa`` (N/m) of rings ``a`` and ``b``: the smaller of their edge stiffnesses ``EA / l_0``,
    or the stiffness that stops their start energies (module doc), whichever is larger."""
    edge = min(model.ea[a] / model.rest_len[a], model.ea[b] / model.rest_len[b])
    reach = pair_reach(model, a, b)
    return max(edge, (model.start_energy[a] + model.start_energy[b]) / (reach * reach * BETA_AT_STOP_GAP))


@kernel(inline="always")
def pair_reach(model, a, b):
    """``dhat = h_a + h_b`` (m): the contact distance of rings ``a`` and ``b``."""
    return model.thickness[a] + model.thickness[b]


# ------------------------------------------------------------------------------------- pairs
@kernel
def _swept_ring_boxes(xa, xb, thickness, rw):
    """``rw.box[r]``: ring ``r``'s box (m) over the motion ``xa -> xb``; ``rw.margin[r] = h_r``."""
    for r in range(xa.shape[0]):
        x_lo = y_lo = math.inf
        x_hi = y_hi = -math.inf
        for i in range(xa.shape[1]):
            x_lo = min(x_lo, xa[r, i, 0], xb[r, i, 0])
            x_hi = max(x_hi, xa[r, i, 0], xb[r, i, 0])
            y_lo = min(y_lo, xa[r, i, 1], xb[r, i, 1])
            y_hi = max(y_hi, xa[r, i, 1], xb[r, i, 1])
        rw.box[r, 0] = x_lo
        rw.box[r, 1] = y_lo
        rw.box[r, 2] = x_hi
        rw.box[r, 3] = y_hi
        rw.margin[r] = thickness[r]


@kernel(inline="always")
def _span_box(xa, xb, r, i, k, out):
    """``out = (xmin, ymin, xmax, ymax)``: the box of nodes ``i`` and ``k`` of ring ``r`` over the
    motion ``xa -> xb``."""
    out[0] = min(xa[r, i, 0], xb[r, i, 0], xa[r, k, 0], xb[r, k, 0])
    out[1] = min(xa[r, i, 1], xb[r, i, 1], xa[r, k, 1], xb[r, k, 1])
    out[2] = max(xa[r, i, 0], xb[r, i, 0], xa[r, k, 0], xb[r, k, 0])
    out[3] = max(xa[r, i, 1], xb[r, i, 1], xa[r, k, 1], xb[r, k, 1])


@kernel(inline="always")
def _boxes_near(p, q, gap):
    """Boxes ``p`` and ``q`` (xmin, ymin, xmax, ymax) within ``gap`` (m) of each other."""
    return p[0] <= q[2] + gap and q[0] <= p[2] + gap and p[1] <= q[3] + gap and q[1] <= p[3] + gap


@kernel
def _pairs_one_way(xa, xb, a, b, dhat, rw, count):
    """Append the pairs (node of ring ``a``, edge of ring ``b``) whose boxes over the motion come
    within ``dhat`` (m): the edges of ``b`` near ``a``'s box are listed first (``rw.near``), then
    each node of ``a`` near ``b``'s box is tested against them. Returns the new count (-1: full)."""
    n = xa.shape[1]
    span = rw.span
    n_near = 0
    for j in range(n):
        _span_box(xa, xb, b, j, next_node(j, n), span[0])
        if _boxes_near(span[0], rw.box[a], dhat):
            rw.near[n_near] = j
            n_near += 1
    for i in range(n):
        _span_box(xa, xb, a, i, i, span[1])
        if not _boxes_near(span[1], rw.box[b], dhat):
            continue
        for k in range(n_near):
            j = rw.near[k]
            _span_box(xa, xb, b, j, next_node(j, n), span[0])
            if not _boxes_near(span[0], span[1], dhat):
                continue
            if count >= rw.pairs.shape[0]:
                return -1
            rw.pairs[count, 0] = a
            rw.pairs[count, 1] = i
            rw.pairs[count, 2] = b
            rw.pairs[count, 3] = j
            count += 1
    return count


@kernel
def find_ring_pairs(model, xa, xb, rw):
    """Candidate (node, edge) pairs of different rings whose nodes move straight from ``xa`` to
    ``xb`` (R, N, 2) m: those whose swept boxes come within the pair's ``dhat``. Into ``rw.pairs``
    (their number in ``rw.n_pairs[0]``); returns it, or -1 if they do not fit."""
    _swept_ring_boxes(xa, xb, model.thickness, rw)
    n_ring_pairs = overlapping_pairs(rw.box, rw.margin, rw.order, rw.left, rw.ring_pairs)
    count = 0
    for p in range(n_ring_pairs):
        a, b = rw.ring_pairs[p, 0], rw.ring_pairs[p, 1]
        dhat = pair_reach(model, a, b)
        count = _pairs_one_way(xa, xb, a, b, dhat, rw, count)
        if count >= 0:
            count = _pairs_one_way(xa, xb, b, a, dhat, rw, count)
        if count < 0:
            break
    rw.n_pairs[0] = max(count, 0)
    return count


@kernel(inline="always")
def _pair_distance2(x, pairs, c):
    """Squared distance (m^2) of pair ``c``'s node from its edge at positions ``x`` (R, N, 2)."""
    a, i, b, j = pairs[c, 0], pairs[c, 1], pairs[c, 2], pairs[c, 3]
    q = next_node(j, x.shape[1])
    return point_edge_distance2(x[a, i, 0], x[a, i, 1], x[b, j, 0], x[b, j, 1], x[b, q, 0], x[b, q, 1])


@kernel
def closest_ratio(model, x, rw):
    """The smallest ``d / dhat`` over the pairs of different rings at ``x`` (R, N, 2) m (inf when no
    pair is within reach of the broad phase; -1 if the candidates do not fit)."""
    count = find_ring_pairs(model, x, x, rw)
    if count < 0:
        return -1.0
    ratio = math.inf
    for c in range(count):
        dhat = pair_reach(model, rw.pairs[c, 0], rw.pairs[c, 2])
        ratio = min(ratio, math.sqrt(_pair_distance2(x, rw.pairs, c)) / dhat)
    return ratio


@kernel
def impact_fraction(xa, xb, pairs, count):
    """First time (fraction of the motion ``xa -> xb`` of every node, in [0, 1]) a node of one ring
    meets an edge of another among the candidate ``pairs``; inf if none does."""
    n = xa.shape[1]
    first = math.inf
    for c in range(count):
        a, i, b, j = pairs[c, 0], pairs[c, 1], pairs[c, 2], pairs[c, 3]
        q = next_node(j, n)
        first = min(first, point_edge_impact(xa[a, i], xb[a, i], xa[b, j], xb[b, j], xa[b, q], xb[b, q]))
    return first


# ------------------------------------------------------------------- energy, force, Hessian
@kernel
def contact_energy(model, x, pairs, count):
    """Barrier energy (J) of the candidate ``pairs`` at positions ``x`` (R, N, 2) m."""
    total = 0.0
    for c in range(count):
        a, b = pairs[c, 0], pairs[c, 2]
        dhat2 = pair_reach(model, a, b) ** 2
        s = _pair_distance2(x, pairs, c)
        if s < dhat2:
            total += pair_stiffness(model, a, b) * dhat2 * beta(s / dhat2)
    return total


@kernel
def contact_energy_by_ring(model, x, rw, out):
    """Add the barrier energy (J) between the rings at ``x`` (R, N, 2) m to ``out`` (R,), each pair's
    half to either of its rings."""
    count = find_ring_pairs(model, x, x, rw)
    for c in range(max(count, 0)):
        e = contact_energy(model, x, rw.pairs[c : c + 1], 1)
        out[rw.pairs[c, 0]] += 0.5 * e
        out[rw.pairs[c, 2]] += 0.5 * e


@kernel
def contact_force(model, x, pairs, count, f, rw):
    """Add ``-grad E`` (N) of the candidate ``pairs`` at ``x`` (R, N, 2) m to ``f`` (R, N, 2); a
    pair at distance 0 adds inf. Returns the number of pairs within ``dhat``."""
    n = x.shape[1]
    active = 0
    for c in range(count):
        a, i, b, j = pairs[c, 0], pairs[c, 1], pairs[c, 2], pairs[c, 3]
        q = next_node(j, n)
        dhat2 = pair_reach(model, a, b) ** 2
        s = _pair_distance2(x, pairs, c)
        if s >= dhat2:
            continue
        if not s > 0.0:
            f[a, i, 0] += math.inf
            continue
        active += 1
        point_edge_derivatives(
            x[a, i, 0], x[a, i, 1], x[b, j, 0], x[b, j, 1], x[b, q, 0], x[b, q, 1], rw.g, rw.hess, rw.scratch
        )
        slope = pair_stiffness(model, a, b) * beta_slope(s / dhat2)
        for d in range(2):
            f[a, i, d] -= slope * rw.g[d]
            f[b, j, d] -= slope * rw.g[2 + d]
            f[b, q, d] -= slope * rw.g[4 + d]
    return active


@kernel
def pair_hessians(model, x, pairs, count, coef, rw):
    """``coef hess E`` (6 x 6, unknowns ``(p, a, b)``) of each candidate pair within ``dhat`` at
    ``x`` into ``rw.hessians[c]`` (``rw.within[c]``: whether it is); ``hess E = kappa (beta'' /
    dhat^2 grad d^2 grad d^2^T + beta' hess d^2)``. Marks the coupled nodes in ``rw.slot`` (>= 0)."""
    n = x.shape[1]
    rw.slot[:, :] = -1
    for c in range(count):
        a, i, b, j = pairs[c, 0], pairs[c, 1], pairs[c, 2], pairs[c, 3]
        q = next_node(j, n)
        dhat2 = pair_reach(model, a, b) ** 2
        s = _pair_distance2(x, pairs, c)
        rw.within[c] = s < dhat2 and s > 0.0
        if not rw.within[c]:
            continue
        point_edge_derivatives(
            x[a, i, 0], x[a, i, 1], x[b, j, 0], x[b, j, 1], x[b, q, 0], x[b, q, 1], rw.g, rw.hess, rw.scratch
        )
        kappa = pair_stiffness(model, a, b)
        ca = coef * kappa * beta_curvature(s / dhat2) / dhat2
        cb = coef * kappa * beta_slope(s / dhat2)
        for k in range(6):
            for m in range(6):
                rw.hessians[c, k, m] = ca * rw.g[k] * rw.g[m] + cb * rw.hess[k, m]
        rw.slot[a, i] = 0
        rw.slot[b, j] = 0
        rw.slot[b, q] = 0


@kernel(inline="always")
def pair_node(pairs, c, k, n):
    """Ring and node of the ``k``-th unknown (0: the node, 1, 2: the edge's ends) of pair ``c``."""
    if k == 0:
        return pairs[c, 0], pairs[c, 1]
    j = pairs[c, 3]
    return pairs[c, 2], (j if k == 1 else next_node(j, n))


@kernel
def add_ring_blocks(pairs, count, r, n, band, pos, rw):
    """Add the blocks of the pairs' Hessians (:func:`pair_hessians`) within ring ``r`` to its band."""
    for c in range(count):
        if not rw.within[c] or (pairs[c, 0] != r and pairs[c, 2] != r):
            continue
        for ka in range(3):
            ra, na = pair_node(pairs, c, ka, n)
            for kb in range(3):
                rb, nb = pair_node(pairs, c, kb, n)
                if ra != r or rb != r:
                    continue
                h = rw.hessians[c]
                band_add_block(
                    band,
                    pos,
                    na,
                    nb,
                    h[2 * ka, 2 * kb],
                    h[2 * ka, 2 * kb + 1],
                    h[2 * ka + 1, 2 * kb],
                    h[2 * ka + 1, 2 * kb + 1],
                )


@kernel
def number_coupled_nodes(rw):
    """Number the coupled nodes (``rw.slot >= 0``) ring by ring: ``rw.slot[r, i]`` becomes the node's
    first column (two per node) of the coupling, ``rw.first[r]`` ring ``r``'s first column
    (``rw.first[R]``: the number of columns). Returns it, or -1 if they do not fit ``rw.cap``."""
    col = 0
    for r in range(rw.slot.shape[0]):
        rw.first[r] = col
        for i in range(rw.slot.shape[1]):
            if rw.slot[r, i] >= 0:
                rw.slot[r, i] = col
                col += 2
    rw.first[rw.slot.shape[0]] = col
    return col if col <= rw.cap.shape[0] else -1


@kernel
def coupling_entries(pairs, count, n, rw):
    """The blocks of the pairs' Hessians between rings as entries of the coupling's rows: entry
    ``e`` adds ``rw.value[e]`` at the row column ``rw.column[e]`` (a coupled node's
    :func:`number_coupled_nodes` column plus its component) and the unknown ``rw.dof[e]`` (``2 node
    + component``) of ring ``rw.ring[e]``. Returns the number of entries."""
    m = 0
    for c in range(count):
        if not rw.within[c]:
            continue
        h = rw.hessians[c]
        for ka in range(3):
            ra, na = pair_node(pairs, c, ka, n)
            for kb in range(3):
                rb, nb = pair_node(pairs, c, kb, n)
                if ra == rb:
                    continue
                for d in range(2):
                    for e in range(2):
                        rw.column[m] = rw.slot[ra, na] + d
                        rw.ring[m] = rb
                        rw.dof[m] = 2 * nb + e
                        rw.value[m] = h[2 * ka + d, 2 * kb + e]
                        m += 1
    return m
