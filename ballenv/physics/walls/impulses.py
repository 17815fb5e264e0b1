"""Contact between rings, and a ring's contact with itself.

Each ring's wall has a thickness ``h``; two walls touch when a node of one ring comes within the
contact distance ``delta = h_a + h_b`` (the paper's "twice the thickness" for equal rings) of the
other ring's centreline. Detection, in three stages:

* **broad phase**: axis-aligned bounding boxes of the rings, grown by the contact distance (plus
  the distance a ring can move in the step), compared by sort-and-sweep along x: only ring pairs
  whose boxes overlap go on, so the cost grows about linearly with the number of spread-out rings;
* **narrow phase**: each node of ring ``a`` inside the (grown) box of ring ``b`` is tested against
  ``b``'s centreline polygon by the crossing number (a ray along +x crosses the polygon an odd number
  of times when the node is inside), and its nearest edge of ``b`` is found in the same pass: edge
  ``j`` (nodes ``j, j+1``), the barycentric coordinate ``t`` of the foot of the perpendicular, and
  the signed distance ``s`` (m; negative inside);
* the node is in contact when ``s < delta``.

Response (the paper's penalty of its section 3.7, made safe for small steps and for
generalized-alpha): a contact of node ``i`` of ring ``a`` with edge ``j`` of ring ``b`` (foot at
barycentric ``t``, outward normal ``n``, relative normal speed ``v_n`` of the node from the foot,
distance ``s`` at the predicted positions ``x0 + dt v0``) gets the impulse

    J = m_eff d / dt,   m_eff = 1 / (1/m_a + ((1 - t)^2 + t^2) / m_b)

along ``n`` on the intruding node, and ``-(1 - t) J n`` and ``-t J n`` on the edge's two nodes:
equal and opposite, so linear momentum is conserved exactly; ``m_eff`` makes the pair's relative
velocity at the foot change by ``d / dt``, so the predicted penetration ``d`` closes in the step.
The impulse acts on the start velocities (a kick), not as the paper's force ``F = m_a d / dt^2``
over the step: generalized-alpha's Newmark update reflects a force that stops a node within one
step and echoes it into the next through its ``alpha_m`` term. A node that enters the contact
distance in the step is stopped on it (the paper's ``d``); one already inside at distance
``s0 = s - dt v_n`` stops approaching and is pushed out at the rate ``1 / RELAXATION_TIME``, since
the paper's ``d = delta - s`` would push it out within one step at a speed ``d / dt`` that grows
without bound as ``dt`` shrinks:

    d = -dt v_n + r (delta - s0),   r = 1 if s0 >= delta else min(1, dt / RELAXATION_TIME).

The impulses are computed at the start of the step (explicit), so the rings are still solved one
by one. They act with ``Scene.self_intersection`` ``"reject"`` and ``"ignore"``; with
``"barrier"``, rings touch through the barrier potential of :mod:`ballenv.physics.walls.ring_barrier` inside
one implicit step of the rings in contact (:mod:`ballenv.physics.step.joint_newton`) instead.

Step acceptance (the stepper calls :func:`rings_intrude` on every trial state): a trial state in
which a node of one ring is inside another ring's centreline is rejected and retried with half the
step, so only early-stage contacts (a node in the other wall's thickness) are ever resolved. This is
stricter than the paper, which also resolves a single vertex-edge intrusion (its figure 3 a) and
rejects the topologies 3 b and c. :func:`collision_step_limit` keeps a step short enough that no
node can cross more than half the contact distance of a nearby ring in it (no tunnelling).

A ring's contact with itself (a fold or a crumple of the wall): each node gets the same impulse
against the nearest edge of its own ring among the ``SELF_CONTACT_WINDOW`` edges on each side that
begin ``SELF_CONTACT_ARC`` contact distances of arc length away (nearer wall is the node's own
neighbourhood: with more nodes than ``pi R / h`` an edge is shorter than ``2 h``, and testing it
would push neighbours apart), at the contact distance ``2 h``, toward the side it is on at the step's start. A
self-crossing state is never accepted: :func:`self_intersects` tests every trial state and the
stepper rejects it (a star-shape test around the centroid proves most states simple in O(N); only
the others pay the O(N^2) segment test). Wall parts far apart along the ring (a ball squashed
flat until its top touches its bottom) get no impulse: the self-contact barrier inside the implicit
step keeps them apart (:mod:`ballenv.physics.walls.self_barrier`, ``Scene.self_intersection = "barrier"``),
or, with ``"reject"``, only the rejection."""

import math
from typing import TYPE_CHECKING

from ..base.cyclic import next_node, prev_node
from ..base.jit import copy_into, kernel
from .broad_phase import overlapping_pairs, ring_boxes

if TYPE_CHECKING:
    from ..scene import Scene

# contact row: ring a, node i of a, ring b, edge j of b (nodes j, j+1), t in [0, 1], signed distance
CONTACT_COLUMNS = 6
CONTACTS_PER_NODE = 6  # other rings a node can touch at once (hexagonal packing)
SELF_CONTACT_WINDOW = 6  # edges on each side of a node searched for contact with its own wall
SELF_CONTACT_ARC = 2.0  # own wall nearer than this many contact distances along the ring is skipped
RELAXATION_TIME = 1e-2  # s: a node found inside the contact distance is pushed out over this time


# ----------------------------------------------------------------------------------- narrow phase
@kernel
def orientation(x):
    """+1 for a counter-clockwise polygon (positive shoelace area), -1 otherwise."""
    a = 0.0
    n = x.shape[0]
    for i in range(n):
        j = next_node(i, n)
        a += x[i, 0] * x[j, 1] - x[j, 0] * x[i, 1]
    return 1.0 if a >= 0.0 else -1.0


@kernel
def locate_point(px, py, poly):
    """Where the point (px, py) lies relative to the closed polygon ``poly`` (N, 2).

    Returns ``(inside, j, t, dist)``: ``inside`` by the crossing number (ray along +x), the nearest
    edge ``j`` (from node j to node j+1), the barycentric coordinate ``t`` in [0, 1] of the foot of
    the perpendicular on it, and the distance (m) to it. One pass over the edges.
    """
    n = poly.shape[0]
    inside = False
    best = math.inf
    best_j = 0
    best_t = 0.0
    for j in range(n):
        k = next_node(j, n)
        ax, ay = poly[j, 0], poly[j, 1]
        bx, by = poly[k, 0], poly[k, 1]
        if (ay > py) != (by > py):
            cross_x = ax + (py - ay) * (bx - ax) / (by - ay)
            if px < cross_x:
                inside = not inside
        ex, ey = bx - ax, by - ay
        length2 = ex * ex + ey * ey
        t = 0.0
        if length2 > 0.0:
            t = min(1.0, max(0.0, ((px - ax) * ex + (py - ay) * ey) / length2))
        dx = px - (ax + t * ex)
        dy = py - (ay + t * ey)
        dist2 = dx * dx + dy * dy
        if dist2 < best:
            best = dist2
            best_j = j
            best_t = t
    return inside, best_j, best_t, math.sqrt(best)


@kernel
def _record_contact(px, py, poly, a, i, b, reach, contacts, count):
    """Locate node ``i`` of ring ``a`` at ``(px, py)`` against ring ``b``'s polygon ``poly``; if
    its signed distance (m, negative inside) is below ``reach``, append the row
    ``(a, i, b, j, t, signed)`` to ``contacts`` (while there is room). Returns the new count."""
    inside, j, t, dist = locate_point(px, py, poly)
    signed = -dist if inside else dist
    if signed < reach and count < contacts.shape[0]:
        row = contacts[count]
        row[0] = a
        row[1] = i
        row[2] = b
        row[3] = j
        row[4] = t
        row[5] = signed
        count += 1
    return count


@kernel
def _pair_contacts(x, a, b, reach, box, contacts, count):
    """Contacts of the nodes of ring ``a`` within ``reach`` (m) of ring ``b``'s centreline."""
    poly = x[b]
    for i in range(x.shape[1]):
        px, py = x[a, i, 0], x[a, i, 1]
        if px < box[b, 0] - reach or px > box[b, 2] + reach:
            continue
        if py < box[b, 1] - reach or py > box[b, 3] + reach:
            continue
        count = _record_contact(px, py, poly, a, i, b, reach, contacts, count)
    return count


@kernel
def find_contacts(x, thickness, cw):
    """Every node within the contact distance ``h_a + h_b`` of another ring's centreline (or inside
    it), as rows of ``cw.contacts`` (see ``CONTACT_COLUMNS``); returns their number.

    Broad phase on the rings' boxes (a pair is kept when its boxes are within the contact
    distance), then the narrow phase both ways for each kept pair.
    """
    for r in range(x.shape[0]):
        cw.margin[r] = thickness[r]
    ring_boxes(x, cw.box)
    n_pairs = overlapping_pairs(cw.box, cw.margin, cw.order, cw.left, cw.pairs)
    count = 0
    for p in range(n_pairs):
        a, b = cw.pairs[p, 0], cw.pairs[p, 1]
        reach = thickness[a] + thickness[b]
        count = _pair_contacts(x, a, b, reach, cw.box, cw.contacts, count)
        count = _pair_contacts(x, b, a, reach, cw.box, cw.contacts, count)
    return count


@kernel
def find_contacts_all_pairs(x, thickness, contacts):
    """The paper's first implementation: every node against every other ring, no broad phase.
    O((R N)^2); the reference :func:`find_contacts` is tested and benchmarked against."""
    count = 0
    n_rings = x.shape[0]
    for a in range(n_rings):
        for b in range(n_rings):
            if a == b:
                continue
            reach = thickness[a] + thickness[b]
            for i in range(x.shape[1]):
                count = _record_contact(x[a, i, 0], x[a, i, 1], x[b], a, i, b, reach, contacts, count)
    return count


# --------------------------------------------------------------------------------------- response
@kernel
def _edge_normal(poly, j, sign):
    """Unit outward normal of edge ``j`` (node j to j+1) of a polygon of orientation ``sign``."""
    q = next_node(j, poly.shape[0])
    ex = poly[q, 0] - poly[j, 0]
    ey = poly[q, 1] - poly[j, 1]
    s = sign / math.sqrt(ex * ex + ey * ey)
    return s * ey, -s * ex


@kernel
def _node_normal(poly, k, sign):
    """Outward unit normal at node ``k``: the mean of its two edges' normals."""
    ax, ay = _edge_normal(poly, prev_node(k, poly.shape[0]), sign)
    bx, by = _edge_normal(poly, k, sign)
    nx, ny = ax + bx, ay + by
    length = math.sqrt(nx * nx + ny * ny)
    if length == 0.0:  # a folded node: its two edges point back on each other
        return bx, by
    return nx / length, ny / length


@kernel
def outward_normal(poly, j, t, sign):
    """Outward unit normal of the polygon at the foot ``t`` on edge ``j``: the node normals of the
    edge's ends interpolated linearly in ``t`` (then normalised), so the direction turns smoothly
    round the polygon and is the same from both edges at a node. It never points from the foot to
    the intruding node: that direction turns a node facing a node sideways (a negative shear
    stiffness), and a jump of the normal between neighbouring edges made the mirror-symmetric
    head-on collision lose its symmetry at round-off ties."""
    q = next_node(j, poly.shape[0])
    ax, ay = _node_normal(poly, j, sign)
    bx, by = _node_normal(poly, q, sign)
    nx = (1.0 - t) * ax + t * bx
    ny = (1.0 - t) * ay + t * by
    length = math.sqrt(nx * nx + ny * ny)
    if length == 0.0:
        return _edge_normal(poly, j, sign)
    return nx / length, ny / length


@kernel
def _kick(v, h, node_mass, a, i, b, j, t, nx, ny, signed, delta, relax, kicked):
    """Add the impulse of a contact of node ``i`` of ring ``a`` with edge ``j`` of ring ``b`` (foot
    ``t``, normal ``(nx, ny)`` toward the node, predicted distance ``signed``) to ``kicked``."""
    q = next_node(j, v.shape[1])
    # normal speed of the node away from the foot, and the distance at the step's start
    vn = nx * (v[a, i, 0] - (1.0 - t) * v[b, j, 0] - t * v[b, q, 0]) + ny * (
        v[a, i, 1] - (1.0 - t) * v[b, j, 1] - t * v[b, q, 1]
    )
    start = signed - h * vn
    d = -h * vn + (1.0 if start >= delta else relax) * (delta - start)
    if d <= 0.0:
        return
    w = (1.0 - t) * (1.0 - t) + t * t
    m_eff = 1.0 / (1.0 / node_mass[a] + w / node_mass[b])
    jn = m_eff * d / h
    ja = jn / node_mass[a]
    jb = jn / node_mass[b]
    kicked[a, i, 0] += ja * nx
    kicked[a, i, 1] += ja * ny
    kicked[b, j, 0] -= (1.0 - t) * jb * nx
    kicked[b, j, 1] -= (1.0 - t) * jb * ny
    kicked[b, q, 0] -= t * jb * nx
    kicked[b, q, 1] -= t * jb * ny


@kernel
def _nearest_own_edge(pred, edge, r, i, step, arc0, best, best_j, best_t):
    """Scan ring ``r``'s edges from node ``i`` along the ring in direction ``step`` (+1 or -1):
    skip the edges whose nearest end lies less than ``arc0`` (m, arc length at the predicted
    positions ``pred``, edge lengths ``edge``) from ``i``, then test the next
    ``SELF_CONTACT_WINDOW``; keep the nearest edge closer than ``sqrt(best)`` at the predicted
    positions. Returns ``(best, best_j, best_t)``."""
    n = pred.shape[1]
    px, py = pred[r, i, 0], pred[r, i, 1]
    arc = 0.0
    tested = 0
    node = i
    for _ in range(n // 2 - 1):
        far = (node + step) % n
        arc += edge[node] if step > 0 else edge[far]
        near, node = far, far
        far = (node + step) % n
        if arc < arc0:
            continue
        j = near if step > 0 else far  # edge (j, j + 1)
        q = next_node(j, n)
        ex, ey = pred[r, q, 0] - pred[r, j, 0], pred[r, q, 1] - pred[r, j, 1]
        length2 = ex * ex + ey * ey
        t = 0.0
        if length2 > 0.0:
            t = min(1.0, max(0.0, ((px - pred[r, j, 0]) * ex + (py - pred[r, j, 1]) * ey) / length2))
        dx = px - pred[r, j, 0] - t * ex
        dy = py - pred[r, j, 1] - t * ey
        if dx * dx + dy * dy < best:
            best = dx * dx + dy * dy
            best_j = j
            best_t = t
        tested += 1
        if tested == SELF_CONTACT_WINDOW:
            break
    return best, best_j, best_t


@kernel
def _self_contacts(x, pred, edge, v, h, r, delta, relax, node_mass, kicked):
    """Impulses between node ``i`` of ring ``r`` and the nearest edge of its own ring closer than
    ``delta`` at the predicted positions, among the ``SELF_CONTACT_WINDOW`` edges on each side that
    begin ``SELF_CONTACT_ARC * delta`` of arc length away from the node (nearer wall cannot touch
    it without a fold sharper than the wall is thick); the normal points to the side the node is on
    at the step's start. ``edge`` (N,) is scratch for the predicted edge lengths (m). Returns the
    number of contacts."""
    n = x.shape[1]
    for j in range(n):
        q = next_node(j, n)
        edge[j] = math.hypot(pred[r, q, 0] - pred[r, j, 0], pred[r, q, 1] - pred[r, j, 1])
    arc0 = SELF_CONTACT_ARC * delta
    count = 0
    for i in range(n):
        best, best_j, best_t = _nearest_own_edge(pred, edge, r, i, 1, arc0, delta * delta, -1, 0.0)
        best, best_j, best_t = _nearest_own_edge(pred, edge, r, i, -1, arc0, best, best_j, best_t)
        if best_j < 0:
            continue
        j = best_j
        q = next_node(j, n)
        ex, ey = x[r, q, 0] - x[r, j, 0], x[r, q, 1] - x[r, j, 1]
        length = math.sqrt(ex * ex + ey * ey)
        if length == 0.0:
            continue
        nx, ny = ey / length, -ex / length
        side = nx * (x[r, i, 0] - x[r, j, 0]) + ny * (x[r, i, 1] - x[r, j, 1])
        if side < 0.0:
            nx, ny = -nx, -ny
        _kick(v, h, node_mass, r, i, r, j, best_t, nx, ny, math.sqrt(best), delta, relax, kicked)
        count += 1
    return count


@kernel
def collision_impulses(x, v, h, thickness, node_mass, rings, self_contact, cw, kicked, kinetic_change, rw):
    """Velocities ``kicked`` (R, N, 2, m/s) after the collision impulses of a step of size ``h``
    (s) from nodes ``x`` (m) moving at ``v`` (m/s): between rings if ``rings`` (``rw``: the
    collision scratch ``cw`` once more, None where rings cannot collide), within each ring if
    ``self_contact``; see the module docstring. ``kinetic_change[r]`` receives the change of ring
    r's kinetic energy (J). Returns the number of contacts (found on the predicted positions
    ``x + h v``, kept in ``cw.predicted``)."""
    copy_into(kicked, v)
    pred = cw.predicted
    for r in range(x.shape[0]):
        for i in range(x.shape[1]):
            for d in range(2):
                pred[r, i, d] = x[r, i, d] + h * v[r, i, d]
    relax = min(1.0, h / RELAXATION_TIME)
    count = 0
    if rings:
        count = ring_kicks(pred, v, h, thickness, node_mass, relax, kicked, rw)
    if self_contact:
        for r in range(x.shape[0]):
            count += _self_contacts(
                x, pred, cw.edge_length, v, h, r, 2.0 * thickness[r], relax, node_mass, kicked
            )
    for r in range(x.shape[0]):
        change = 0.0
        for i in range(x.shape[1]):
            for k in range(2):
                change += kicked[r, i, k] * kicked[r, i, k] - v[r, i, k] * v[r, i, k]
        kinetic_change[r] = 0.5 * node_mass[r] * change
    return count


@kernel
def ring_kicks(pred, v, h, thickness, node_mass, relax, kicked, rw):
    """The impulses between rings found on the predicted positions ``pred`` (m) into ``kicked`` (see
    :func:`collision_impulses`); returns their number. Nothing (0) without ``rw``."""
    if rw is None:
        return 0
    for r in range(pred.shape[0]):
        rw.orientation[r] = orientation(pred[r])
    count = find_contacts(pred, thickness, rw)
    for c in range(count):
        row = rw.contacts[c]
        a, i, b, j = int(row[0]), int(row[1]), int(row[2]), int(row[3])
        nx, ny = outward_normal(pred[b], j, row[4], rw.orientation[b])
        reach = thickness[a] + thickness[b]
        _kick(v, h, node_mass, a, i, b, j, row[4], nx, ny, row[5], reach, relax, kicked)
    return count


@kernel
def rings_intrude(x, thickness, cw):
    """True if a node of one ring is inside another ring's centreline polygon (False without
    ``cw``, the ring-ring scratch ``Workspace.ring_pairs``)."""
    if cw is None:
        return False
    count = find_contacts(x, thickness, cw)
    for c in range(count):
        if cw.contacts[c, 5] < 0.0:
            return True
    return False


@kernel
def collision_step_limit(x, v, thickness, h, cw):
    """Largest step (s, at most ``h``) in which no node can move more than half the contact
    distance into a ring it could reach; ``h`` itself without ``cw`` (the ring-ring scratch
    ``Workspace.ring_pairs``, None where rings cannot collide).

    For each pair whose boxes, grown by the contact distance plus the distance its fastest node
    covers in ``h``, overlap: the gap ``G`` between the tight boxes bounds every node distance from
    below; the pair's closing speed is bounded by ``u = |v_cm,a - v_cm,b| + dev_a + dev_b`` (``dev``:
    a ring's largest node speed relative to its centre of mass: spin and deformation). The step is
    kept below ``(max(G - delta, 0) + delta / 2) / u``.
    """
    if cw is None:
        return h
    n_rings, n = x.shape[0], x.shape[1]
    for r in range(n_rings):
        cx = cy = vx = vy = 0.0
        for i in range(n):
            cx += x[r, i, 0]
            cy += x[r, i, 1]
            vx += v[r, i, 0]
            vy += v[r, i, 1]
        vx /= n
        vy /= n
        fastest = 0.0
        dev = 0.0
        for i in range(n):
            fastest = max(fastest, math.hypot(v[r, i, 0], v[r, i, 1]))
            dev = max(dev, math.hypot(v[r, i, 0] - vx, v[r, i, 1] - vy))
        cw.velocity[r, 0] = vx
        cw.velocity[r, 1] = vy
        cw.velocity[r, 2] = dev
        cw.margin[r] = 2.0 * thickness[r] + fastest * h
    ring_boxes(x, cw.box)
    n_pairs = overlapping_pairs(cw.box, cw.margin, cw.order, cw.left, cw.pairs)
    limit = h
    for p in range(n_pairs):
        a, b = cw.pairs[p, 0], cw.pairs[p, 1]
        gap = -math.inf
        for c in range(2):
            gap = max(gap, cw.box[b, c] - cw.box[a, c + 2], cw.box[a, c] - cw.box[b, c + 2])
        delta = thickness[a] + thickness[b]
        u = (
            math.hypot(cw.velocity[a, 0] - cw.velocity[b, 0], cw.velocity[a, 1] - cw.velocity[b, 1])
            + cw.velocity[a, 2]
            + cw.velocity[b, 2]
        )
        if u > 0.0:
            limit = min(limit, (max(gap - delta, 0.0) + 0.5 * delta) / u)
    return limit


# ----------------------------------------------------------------------------------- self-contact
@kernel
def _star_shaped(x):
    """True if every node is seen from the centroid at a strictly increasing angle (one turn):
    the polygon is then star-shaped about its centroid, hence simple. O(N)."""
    n = x.shape[0]
    cx = cy = 0.0
    for i in range(n):
        cx += x[i, 0]
        cy += x[i, 1]
    cx /= n
    cy /= n
    sign = orientation(x)
    turn = 0.0
    for i in range(n):
        j = next_node(i, n)
        ax, ay = x[i, 0] - cx, x[i, 1] - cy
        bx, by = x[j, 0] - cx, x[j, 1] - cy
        cross = sign * (ax * by - ay * bx)
        if not cross > 0.0:
            return False
        turn += math.atan2(cross, ax * bx + ay * by)
    return abs(turn - 2.0 * math.pi) < 1e-6


@kernel
def _segments_cross(ax, ay, bx, by, cx, cy, dx, dy):
    """True if the closed segments ab and cd share a point (orientation test)."""
    d1 = (dx - cx) * (ay - cy) - (dy - cy) * (ax - cx)
    d2 = (dx - cx) * (by - cy) - (dy - cy) * (bx - cx)
    d3 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    d4 = (bx - ax) * (dy - ay) - (by - ay) * (dx - ax)
    return ((d1 > 0.0) != (d2 > 0.0) or d1 == 0.0 or d2 == 0.0) and (
        (d3 > 0.0) != (d4 > 0.0) or d3 == 0.0 or d4 == 0.0
    )


@kernel
def self_intersects(x):
    """True if two non-adjacent edges of the ring's polygon ``x`` (N, 2) cross or touch."""
    if _star_shaped(x):
        return False
    n = x.shape[0]
    for i in range(n):
        i1 = next_node(i, n)
        for j in range(i + 2, n):
            j1 = next_node(j, n)
            if j1 == i:
                continue
            if max(x[i, 0], x[i1, 0]) < min(x[j, 0], x[j1, 0]):
                continue
            if max(x[j, 0], x[j1, 0]) < min(x[i, 0], x[i1, 0]):
                continue
            if max(x[i, 1], x[i1, 1]) < min(x[j, 1], x[j1, 1]):
                continue
            if max(x[j, 1], x[j1, 1]) < min(x[i, 1], x[i1, 1]):
                continue
            if _segments_cross(x[i, 0], x[i, 1], x[i1, 0], x[i1, 1], x[j, 0], x[j, 1], x[j1, 0], x[j1, 1]):
                return True
    return False


def enabled(scene: "Scene") -> bool:
    """Two or more rings that collide (``Scene.ring_collision``)."""
    return len(scene.rings) > 1 and scene.ring_collision
