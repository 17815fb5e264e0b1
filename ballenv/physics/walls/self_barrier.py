"""A ring's contact with its own far wall: a smooth barrier potential inside the Newton solve.

Two parts of one ring's centreline that are far apart along the ring (a ball squashed until its top
touches its bottom, a crumpled wall) repel through the potential of Incremental Potential Contact
(Li et al., ACM TOG 2020) on the distance ``d`` (m) between a node ``p`` and an edge ``(a, b)``:

    E = kappa dhat^2 beta(d^2 / dhat^2),   beta(y) = -(y - 1)^2 ln y   (0 < y < 1; 0 for y >= 1)

with ``dhat`` = the wall thickness ``h`` (m; the barrier acts while the two centrelines are closer
than one wall thickness) and

    kappa = max(EA / l_0, K_0 / (dhat^2 beta(STOP_GAP^2)))                         [N/m]

the axial stiffness of one edge (the barrier about as stiff as the wall it keeps apart) or, if
larger, the stiffness at which the ring's kinetic energy at the start ``K_0`` (J,
``Model.start_energy``) is spent before a pair comes closer than ``STOP_GAP dhat``. The log grows
slowly: at ``EA / l_0`` alone a thin wall thrown at 20-30 m/s had node-edge pairs pushed to 1e-5
``dhat``, where round-off decides whether even a 1 ns step crosses the wall. (IPC raises its
stiffness during a run when distances get that small; fixed for the run, the potential stays
conservative.) ``E`` (J) is ``C^2`` in the positions, zero
with its first two derivatives at ``d = dhat``, and grows without bound as ``d -> 0``: the
potential is conservative (its energy is part of the ring's energy budget) and no state with
``d = 0`` has finite energy. ``d^2`` is the squared distance from ``p`` to the segment: to the line
through ``a, b`` where the foot lies between them, ``d^2 = ((b - a) x (p - a))^2 / |b - a|^2``,
else to the nearer end. The force ``-grad E`` and the exact Hessian

    hess E = kappa (beta''(y) / dhat^2 grad d^2 (grad d^2)^T + beta'(y) hess d^2)

enter the Newton system of the implicit step like any other force.

**Pairs.** A node is paired with the edges that begin at least ``ARC_EXCLUSION dhat`` of rest arc
length (and are not its own two edges) away along the ring on either side: nearer wall is the
node's own neighbourhood, which bending and stretching hold apart. A broad phase (sort and sweep
of the edges' boxes along x, swept over the motion of a Newton correction and grown by ``dhat``)
lists the candidate pairs; with none, the barrier costs the sweep and nothing else (the force, the
Jacobian and the step are those without it, bit for bit).

**Structure.** The blocks of a pair that couple nodes within four zig-zag positions of each other
go into the band; the others (a node and an edge far along the ring) are gathered by row node:
node ``k``'s off-band row is two low-rank columns ``e_{2k+d} w_{k,d}^T`` (``e`` a unit column), so
the Jacobian stays a band plus ``2 K`` low-rank columns for ``K`` nodes with off-band coupling and
is solved by the Woodbury identity (:func:`base.linalg.solve_band_wide_low_rank`) in
``O(N (w + K) K + K^3)``.

**Line search filter.** Every Newton correction (and the predictor) is a straight motion of the
nodes; continuous collision detection (:func:`point_edge_impact`: the first time a node meets a
moving edge, a root of a quadratic) over the candidate pairs shortens it to ``CCD_SAFETY`` of the
first impact, so no trial state passes a wall through another, however far it moves.
"""

import math

from ..base.cyclic import next_node
from ..base.jit import copy_into, kernel
from ..base.linalg import band_add_block
from .broad_phase import sort_by

ARC_EXCLUSION = 2.0  # pairs nearer along the ring (rest arc length) than this many dhat are skipped
MIN_ARC_EDGES = 1  # and pairs nearer than this many edges (a node and its own two edges)
CCD_SAFETY = 0.8  # a correction that would make a node meet an edge is cut to this fraction
BAND_REACH = 4  # node blocks within this many zig-zag positions fit the band (linalg.BAND_HALF_WIDTH)
PAIRS_PER_NODE = 16  # room for candidate pairs
STOP_GAP = 0.1  # the start energy alone cannot push a pair closer than this fraction of dhat


# ----------------------------------------------------------------------------- the potential
@kernel(inline="always")
def beta(y):
    """``beta(y) = -(y - 1)^2 ln y`` for ``0 < y < 1``, 0 above, inf at or below 0."""
    if y >= 1.0:
        return 0.0
    if not y > 0.0:
        return math.inf
    return -(y - 1.0) * (y - 1.0) * math.log(y)


BETA_AT_STOP_GAP = beta.py_func(STOP_GAP**2)  # the potential (per kappa dhat^2) at STOP_GAP dhat


@kernel(inline="always")
def beta_slope(y):
    """``beta'(y) = -2 (y - 1) ln y - (y - 1)^2 / y`` (0 above 1)."""
    if y >= 1.0:
        return 0.0
    return -2.0 * (y - 1.0) * math.log(y) - (y - 1.0) * (y - 1.0) / y


@kernel(inline="always")
def beta_curvature(y):
    """``beta''(y) = -2 ln y - 4 (y - 1) / y + (y - 1)^2 / y^2`` (0 above 1)."""
    if y >= 1.0:
        return 0.0
    return -2.0 * math.log(y) - 4.0 * (y - 1.0) / y + (y - 1.0) * (y - 1.0) / (y * y)


@kernel(inline="always")
def stiffness(model, r):
    """``kappa`` (N/m) of ring ``r``: ``max(EA / l_0, K_0 / (dhat^2 BETA_AT_STOP_GAP))`` (module doc)."""
    stop = model.start_energy[r] / (model.thickness[r] ** 2 * BETA_AT_STOP_GAP)
    return max(model.ea[r] / model.rest_len[r], stop)


@kernel(inline="always")
def reach(model, r):
    """``dhat`` (m): the wall thickness of ring ``r``."""
    return model.thickness[r]


# ------------------------------------------------------------------------------ the distance
@kernel
def point_edge_distance2(px, py, ax, ay, bx, by):
    """Squared distance (m^2) from ``p`` to the segment ``ab``."""
    ex, ey = bx - ax, by - ay
    qx, qy = px - ax, py - ay
    length2 = ex * ex + ey * ey
    t = (qx * ex + qy * ey) / length2 if length2 > 0.0 else 0.0
    if t <= 0.0:
        return qx * qx + qy * qy
    if t >= 1.0:
        return (px - bx) * (px - bx) + (py - by) * (py - by)
    c = ex * qy - ey * qx
    return c * c / length2


@kernel
def _point_point(s, g, hess, i, sx, sy):
    """``d^2 = |z_0 - z_i|^2`` (``i``: 2 for ``a``, 4 for ``b``; ``(sx, sy) = z_0 - z_i``)."""
    g[0], g[1] = 2.0 * sx, 2.0 * sy
    g[i], g[i + 1] = -2.0 * sx, -2.0 * sy
    for d in range(2):
        hess[d, d] = 2.0
        hess[i + d, i + d] = 2.0
        hess[d, i + d] = -2.0
        hess[i + d, d] = -2.0
    return s


@kernel
def point_edge_derivatives(px, py, ax, ay, bx, by, g, hess, scratch):
    """Squared distance ``s`` (m^2) from ``p`` to the segment ``ab``; its gradient into ``g`` (6,)
    and Hessian into ``hess`` (6, 6), in the unknowns ``z = (p, a, b)``. ``scratch`` is (6, 6).

    On the line piece ``s = c^2 / L``, ``c = e x q``, ``e = b - a``, ``q = p - a``, ``L = |e|^2``:
    ``grad s = 2 c grad c / L - c^2 grad L / L^2`` and
    ``hess s = 2 (grad c grad c^T + c hess c) / L - 2 c (grad c grad L^T + grad L grad c^T) / L^2
    - c^2 hess L / L^2 + 2 c^2 grad L grad L^T / L^3`` (``c`` bilinear, ``L`` quadratic: their
    Hessians are constant)."""
    for k in range(6):
        g[k] = 0.0
        for m in range(6):
            hess[k, m] = 0.0
    ex, ey = bx - ax, by - ay
    qx, qy = px - ax, py - ay
    length2 = ex * ex + ey * ey
    t = (qx * ex + qy * ey) / length2 if length2 > 0.0 else 0.0
    if t <= 0.0:
        return _point_point(qx * qx + qy * qy, g, hess, 2, qx, qy)
    if t >= 1.0:
        sx, sy = px - bx, py - by
        return _point_point(sx * sx + sy * sy, g, hess, 4, sx, sy)
    c = ex * qy - ey * qx
    gc = scratch[0]
    gl = scratch[1]
    gc[0], gc[1], gc[2], gc[3], gc[4], gc[5] = -ey, ex, ey - qy, qx - ex, qy, -qx
    gl[0], gl[1], gl[2], gl[3], gl[4], gl[5] = 0.0, 0.0, -2.0 * ex, -2.0 * ey, 2.0 * ex, 2.0 * ey
    # hess c: c = e_x q_y - e_y q_x with e = b - a, q = p - a (rows of scratch[2:6]: De_x, De_y, Dq_x, Dq_y)
    dex, dey, dqx, dqy = scratch[2], scratch[3], scratch[4], scratch[5]
    for k in range(6):
        dex[k] = dey[k] = dqx[k] = dqy[k] = 0.0
    dex[2], dex[4] = -1.0, 1.0
    dey[3], dey[5] = -1.0, 1.0
    dqx[0], dqx[2] = 1.0, -1.0
    dqy[1], dqy[3] = 1.0, -1.0
    inv = 1.0 / length2
    for k in range(6):
        g[k] = 2.0 * c * gc[k] * inv - c * c * gl[k] * inv * inv
        for m in range(6):
            hc = dex[k] * dqy[m] + dqy[k] * dex[m] - dey[k] * dqx[m] - dqx[k] * dey[m]
            hl = 2.0 * (dex[k] * dex[m] + dey[k] * dey[m])
            hess[k, m] = (
                2.0 * (gc[k] * gc[m] + c * hc) * inv
                - 2.0 * c * (gc[k] * gl[m] + gl[k] * gc[m]) * inv * inv
                - c * c * hl * inv * inv
                + 2.0 * c * c * gl[k] * gl[m] * inv * inv * inv
            )
    return c * c * inv


# ------------------------------------------------------------------------------------- pairs
@kernel(inline="always")
def _ring_gap(i, j, n):
    """Edges between nodes ``i`` and ``j`` along the ring (the shorter way)."""
    k = abs(i - j)
    return min(k, n - k)


@kernel(inline="always")
def excluded(i, j, n, rest_len, dhat):
    """True if node ``i`` and edge ``(j, j + 1)`` are too near along the ring to be paired."""
    k = min(_ring_gap(i, j, n), _ring_gap(i, next_node(j, n), n))
    return k < MIN_ARC_EDGES or k * rest_len < ARC_EXCLUSION * dhat


@kernel
def _node_boxes(xa, xb, box):
    """``box[i] = (xmin, ymin, xmax, ymax)`` (m) of node ``i`` over its straight motion xa -> xb."""
    for i in range(xa.shape[0]):
        box[i, 0] = min(xa[i, 0], xb[i, 0])
        box[i, 1] = min(xa[i, 1], xb[i, 1])
        box[i, 2] = max(xa[i, 0], xb[i, 0])
        box[i, 3] = max(xa[i, 1], xb[i, 1])


@kernel(inline="always")
def _near(box, i, j, k, dhat):
    """Node ``i``'s box within ``dhat`` (m) of the box of nodes ``j``, ``k``."""
    x_lo = min(box[j, 0], box[k, 0]) - dhat
    y_lo = min(box[j, 1], box[k, 1]) - dhat
    x_hi = max(box[j, 2], box[k, 2]) + dhat
    y_hi = max(box[j, 3], box[k, 3]) + dhat
    return box[i, 0] <= x_hi and box[i, 2] >= x_lo and box[i, 1] <= y_hi and box[i, 3] >= y_lo


@kernel(inline="always")
def _add_pair(bw, i, j, n, rest_len, dhat, count):
    """Append (node ``i``, edge ``j``) if it is not excluded and its boxes are near; new count
    (``-1`` when the table is full)."""
    if count < 0 or excluded(i, j, n, rest_len, dhat) or not _near(bw.box, i, j, next_node(j, n), dhat):
        return count
    if count >= bw.pairs.shape[0]:
        return -1
    bw.pairs[count, 0] = i
    bw.pairs[count, 1] = j
    return count + 1


@kernel
def find_pairs(xa, xb, rest_len, dhat, bw):
    """Candidate (node, edge) pairs of one ring whose nodes move straight from ``xa`` to ``xb``
    (N, 2) m: those whose swept boxes come within ``dhat`` (m) and that are not excluded along the
    ring. Sort and sweep on the edges' left box edges (``bw.order`` keeps the last order: nearly
    sorted, O(N)). Into ``bw.pairs``; returns their number (``-1`` if they do not fit)."""
    n = xa.shape[0]
    box = bw.box
    _node_boxes(xa, xb, box)
    order = bw.order
    for k in range(n):
        j = order[k]
        bw.left[j] = min(box[j, 0], box[next_node(j, n), 0])
    sort_by(order, bw.left)
    count = 0
    for k in range(n):
        e = order[k]
        right = max(box[e, 2], box[next_node(e, n), 2]) + dhat
        for m in range(k + 1, n):
            f = order[m]
            if bw.left[f] > right:
                break
            count = _add_pair(bw, e, f, n, rest_len, dhat, count)
            count = _add_pair(bw, f, e, n, rest_len, dhat, count)
    return count


@kernel
def near_pairs(x, rest_len, dhat, bw):
    """How many (node, edge) pairs of one ring at ``x`` (N, 2) m are closer than ``dhat`` (m);
    ``-1`` if the candidates do not fit ``bw.pairs``.

    The answer depends on ``x``, ``rest_len`` and ``dhat`` only, and a step asks it three times of
    the same positions where no wall part comes near (the end of a step, its energy, the start of
    the next): positions found clear are kept (``bw.clear_x``, ``bw.clear_key``), and asking again
    of the same positions, bit for bit, costs a comparison instead of a sweep."""
    if _known_clear(x, rest_len, dhat, bw):
        return 0
    count = find_pairs(x, x, rest_len, dhat, bw)
    if count < 0:
        return count
    n = x.shape[0]
    near = 0
    for c in range(count):
        i, j = bw.pairs[c, 0], bw.pairs[c, 1]
        q = next_node(j, n)
        if point_edge_distance2(x[i, 0], x[i, 1], x[j, 0], x[j, 1], x[q, 0], x[q, 1]) < dhat * dhat:
            near += 1
    if near == 0:
        copy_into(bw.clear_x, x)
        bw.clear_key[0] = rest_len
        bw.clear_key[1] = dhat
    return near


@kernel(inline="always")
def _known_clear(x, rest_len, dhat, bw):
    """Whether ``x`` with ``rest_len`` and ``dhat`` are the positions :func:`near_pairs` last found
    clear (compared bit for bit)."""
    if bw.clear_key[0] != rest_len or bw.clear_key[1] != dhat:
        return False
    clear = bw.clear_x
    for i in range(x.shape[0]):
        if x[i, 0] != clear[i, 0] or x[i, 1] != clear[i, 1]:
            return False
    return True


# ---------------------------------------------------------------------- continuous detection
@kernel
def _smallest_root(c0, c1, c2):
    """Smallest root in [0, 1] of ``c0 + c1 t + c2 t^2`` (inf if none), and the next one."""
    scale = abs(c0) + abs(c1) + abs(c2)
    if scale == 0.0:
        return 0.0, 0.0
    if abs(c2) <= 1e-14 * scale:
        if abs(c1) <= 1e-14 * scale:
            return math.inf, math.inf
        t = -c0 / c1
        return (t, math.inf) if 0.0 <= t <= 1.0 else (math.inf, math.inf)
    disc = c1 * c1 - 4.0 * c2 * c0
    if disc < 0.0:
        return math.inf, math.inf
    q = -0.5 * (c1 + math.copysign(math.sqrt(disc), c1))
    t1 = q / c2
    t2 = c0 / q if q != 0.0 else t1
    lo, hi = min(t1, t2), max(t1, t2)
    first = lo if 0.0 <= lo <= 1.0 else math.inf
    second = hi if 0.0 <= hi <= 1.0 else math.inf
    return (first, second) if first < math.inf else (second, math.inf)


@kernel
def _on_segment_at(t, pa, pb, aa, ab, ba, bb):
    """At time ``t`` of the straight motions (``pa -> pb`` etc., (2,) each): is ``p`` on the
    closed segment ``a b`` (given it is on its line)?"""
    px = pa[0] + t * (pb[0] - pa[0])
    py = pa[1] + t * (pb[1] - pa[1])
    ax = aa[0] + t * (ab[0] - aa[0])
    ay = aa[1] + t * (ab[1] - aa[1])
    bx = ba[0] + t * (bb[0] - ba[0])
    by = ba[1] + t * (bb[1] - ba[1])
    ex, ey = bx - ax, by - ay
    length2 = ex * ex + ey * ey
    if length2 == 0.0:
        return (px - ax) ** 2 + (py - ay) ** 2 == 0.0
    u = ((px - ax) * ex + (py - ay) * ey) / length2
    return -1e-12 <= u <= 1.0 + 1e-12


@kernel
def point_edge_impact(pa, pb, aa, ab, ba, bb):
    """First time ``t`` in [0, 1] at which a node moving straight from ``pa`` to ``pb`` lies on an
    edge whose ends move straight from ``aa`` to ``ab`` and ``ba`` to ``bb`` (each (2,) m); inf if
    it never does. The node is on the edge's line when ``c(t) = e(t) x q(t) = 0`` (``e = b - a``,
    ``q = p - a``), a quadratic in ``t``; a root counts if the node's foot lies on the segment."""
    e0x, e0y = ba[0] - aa[0], ba[1] - aa[1]
    q0x, q0y = pa[0] - aa[0], pa[1] - aa[1]
    dex = (bb[0] - ab[0]) - e0x
    dey = (bb[1] - ab[1]) - e0y
    dqx = (pb[0] - ab[0]) - q0x
    dqy = (pb[1] - ab[1]) - q0y
    c0 = e0x * q0y - e0y * q0x
    c1 = e0x * dqy + dex * q0y - e0y * dqx - dey * q0x
    c2 = dex * dqy - dey * dqx
    first, second = _smallest_root(c0, c1, c2)
    if first < math.inf and _on_segment_at(first, pa, pb, aa, ab, ba, bb):
        return first
    if second < math.inf and _on_segment_at(second, pa, pb, aa, ab, ba, bb):
        return second
    return math.inf


@kernel
def impact_fraction(xa, xb, pairs, count):
    """Smallest impact time (fraction of the motion ``xa -> xb``, in [0, 1]) over the candidate
    pairs, or inf when no node meets an edge."""
    n = xa.shape[0]
    first = math.inf
    for c in range(count):
        i, j = pairs[c, 0], pairs[c, 1]
        q = next_node(j, n)
        first = min(first, point_edge_impact(xa[i], xb[i], xa[j], xb[j], xa[q], xb[q]))
    return first


# ------------------------------------------------------------------- energy, force, Jacobian
@kernel
def barrier_energy(x, pairs, count, kappa, dhat):
    """Barrier energy (J) of the candidate pairs at positions ``x`` (N, 2) m."""
    n = x.shape[0]
    total = 0.0
    dhat2 = dhat * dhat
    for c in range(count):
        i, j = pairs[c, 0], pairs[c, 1]
        q = next_node(j, n)
        s = point_edge_distance2(x[i, 0], x[i, 1], x[j, 0], x[j, 1], x[q, 0], x[q, 1])
        if s < dhat2:
            total += kappa * dhat2 * beta(s / dhat2)
    return total


@kernel
def barrier_force(x, pairs, count, kappa, dhat, f, bw):
    """Add ``-grad E`` (N) of the candidate pairs at ``x`` to ``f``; a pair at distance 0 adds inf.
    Returns the number of pairs within ``dhat``."""
    n = x.shape[0]
    dhat2 = dhat * dhat
    active = 0
    for c in range(count):
        i, j = pairs[c, 0], pairs[c, 1]
        q = next_node(j, n)
        s = point_edge_distance2(x[i, 0], x[i, 1], x[j, 0], x[j, 1], x[q, 0], x[q, 1])
        if s >= dhat2:
            continue
        if not s > 0.0:
            f[i, 0] += math.inf
            continue
        active += 1
        point_edge_derivatives(
            x[i, 0], x[i, 1], x[j, 0], x[j, 1], x[q, 0], x[q, 1], bw.g, bw.hess, bw.scratch
        )
        slope = kappa * beta_slope(s / dhat2)
        for d in range(2):
            f[i, d] -= slope * bw.g[d]
            f[j, d] -= slope * bw.g[2 + d]
            f[q, d] -= slope * bw.g[4 + d]
    return active


@kernel(inline="always")
def _off_band_row(bw, u, w, node, rank, n2):
    """The low-rank columns of ``node``'s off-band row: allocated (unit columns ``e_{2 node + d}``
    into ``u``, zeroed ``w``) on first use. Returns (first column, new rank)."""
    col = bw.slot[node]
    if col >= 0:
        return col, rank
    bw.slot[node] = rank
    for d in range(2):
        for k in range(n2):
            u[k, rank + d] = 0.0
            w[k, rank + d] = 0.0
        u[2 * node + d, rank + d] = 1.0
    return rank, rank + 2


@kernel
def barrier_jacobian(x, pairs, count, kappa, dhat, coef, band, pos, u, w, rank, bw):
    """Add ``coef hess E`` of the candidate pairs at ``x``: node blocks within ``BAND_REACH``
    zig-zag positions into ``band``, the others as low-rank columns ``u w^T`` from column ``rank``
    on (``u``: unit columns, two per node with off-band blocks, ``w``: that node's off-band row).
    Returns the new rank."""
    n = x.shape[0]
    dhat2 = dhat * dhat
    for k in range(n):
        bw.slot[k] = -1
    for c in range(count):
        i, j = pairs[c, 0], pairs[c, 1]
        q = next_node(j, n)
        s = point_edge_distance2(x[i, 0], x[i, 1], x[j, 0], x[j, 1], x[q, 0], x[q, 1])
        if s >= dhat2 or not s > 0.0:
            continue
        point_edge_derivatives(
            x[i, 0], x[i, 1], x[j, 0], x[j, 1], x[q, 0], x[q, 1], bw.g, bw.hess, bw.scratch
        )
        y = s / dhat2
        a = coef * kappa * beta_curvature(y) / dhat2
        b = coef * kappa * beta_slope(y)
        nodes = bw.nodes
        nodes[0], nodes[1], nodes[2] = i, j, q
        for ka in range(3):
            for kb in range(3):
                na, nb = nodes[ka], nodes[kb]
                h00 = a * bw.g[2 * ka] * bw.g[2 * kb] + b * bw.hess[2 * ka, 2 * kb]
                h01 = a * bw.g[2 * ka] * bw.g[2 * kb + 1] + b * bw.hess[2 * ka, 2 * kb + 1]
                h10 = a * bw.g[2 * ka + 1] * bw.g[2 * kb] + b * bw.hess[2 * ka + 1, 2 * kb]
                h11 = a * bw.g[2 * ka + 1] * bw.g[2 * kb + 1] + b * bw.hess[2 * ka + 1, 2 * kb + 1]
                if abs(pos[na] - pos[nb]) <= BAND_REACH:
                    band_add_block(band, pos, na, nb, h00, h01, h10, h11)
                    continue
                col, rank = _off_band_row(bw, u, w, na, rank, 2 * n)
                w[2 * nb, col] += h00
                w[2 * nb + 1, col] += h01
                w[2 * nb, col + 1] += h10
                w[2 * nb + 1, col + 1] += h11
    return rank
