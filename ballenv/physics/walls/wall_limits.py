"""Limits of a ring's wall shape that the self-contact barrier's pairs leave out: a fold shut at one
node and an edge collapsed to a point.

The self-contact barrier (:mod:`ballenv.physics.walls.self_barrier`) pairs a node only with edges some wall
thicknesses away along the ring, so nothing but bending resists node ``i + 1`` folding back onto edge ``(i -
1, i)`` (a turning angle ``phi_i -> +-pi``) and nothing but stretching an edge shrinking to zero length; a
hard impact can do both, and the step size then collapses on states that bending's ``atan2`` and
the self-crossing test cannot tell apart. With the barrier on (``Scene.self_intersection =
"barrier"``), two more IPC potentials (``beta(y) = -(y - 1)^2 ln y``, :func:`walls.self_barrier.beta`) act,
each only near its limit, so a ring that never folds or collapses that far is not changed at all:

* **Fold limit**, per node: with ``u = 1 + cos(phi)`` (0 folded shut, 2 straight) and ``u_on = 1 +
  cos(FOLD_ON)``,

      E_f = k_f beta(u / u_on),   k_f = max(2 u_on EA l0, K_0 / beta(STOP_Y))      [J]

  active while ``|phi| > FOLD_ON``. For a fold of ``theta = pi - |phi|`` the next node is at
  ``d ~ l0 theta`` from the previous edge's line and ``u ~ theta^2 / 2 = d^2 / (2 l0^2)``: ``E_f``
  is the self-contact barrier ``kappa dhat^2 beta(d^2 / dhat^2)`` with ``kappa = EA / l0`` and
  ``dhat^2 = 2 u_on l0^2``. With ``dE/dphi`` and ``d2E/dphi2`` (``du/dphi = -sin(phi)``,
  ``d2u/dphi2 = -cos(phi)``), ``grad E = E' grad phi`` and ``hess E = E'' grad phi grad phi^T + E'
  hess phi`` (bending's ``grad phi``, ``hess phi``: :mod:`.effects.bending`).
* **Collapse limit**, per edge of length ``L``: with ``s = COLLAPSE_ON l0``,

      E_c = k_c beta(L^2 / s^2),   k_c = max(EA s^2 / l0, K_0 / beta(STOP_Y))     [J]

  active while ``L < s`` (the self-contact barrier with ``kappa = EA / l0``, ``dhat = s``, ``d =
  L``). ``grad L^2 = 2 e`` at the edge's end, ``-2 e`` at its start.

With ``K_0`` the ring's kinetic energy at the start (J, ``Model.start_energy``): where the wall's
own stiffness is too soft to spend it, ``k`` is raised so that it is spent before ``y`` falls to
``STOP_Y`` (a fold of at most 171 degrees, an edge of at least 0.079 ``l0``), as the self-contact
barrier's ``kappa`` is (:func:`walls.self_barrier.stiffness`): a thick, soft ring thrown at 15-30 m/s had
edges crushed to 1e-6 ``l0``, where bending's turning angles change by tens of degrees over a 1 ns step.
Both grow without bound at the limit (``phi = +-pi``, ``L = 0``), so no state with finite energy
reaches it; their energy is part of the self-contact energy of the energy budget
(:func:`step.energy_budget.self_contact_energy`). A straight motion of the nodes (a Newton correction, the
predictor) may still jump over a limit: :func:`limit_fraction` cuts it to ``CCD_SAFETY`` of the
first time a node's two edges turn antiparallel (the fold's cross product ``e1 x e2 = 0`` with
``e1 . e2 < 0``, a root of a quadratic) or an edge shrinks to ``SHRINK_FLOOR`` of its length.
"""

import math

from ..base.cyclic import next_node, prev_node
from ..base.jit import kernel
from ..base.linalg import band_add_block
from ..effects.bending import _direction_gradients, _edges, add_turning_blocks, turning_of
from .self_barrier import CCD_SAFETY, _smallest_root, beta, beta_curvature, beta_slope

FOLD_ON = math.radians(150.0)  # rad: turning angle beyond which the fold limit acts
FOLD_U = 1.0 + math.cos(FOLD_ON)  # u_on
COLLAPSE_ON = 0.25  # edge length (fraction of l0) below which the collapse limit acts
SHRINK_FLOOR = 0.1  # a motion may shrink an edge to this fraction of its length, no further
STOP_Y = 0.1  # the start energy alone cannot push y = u / u_on or L^2 / s^2 below this
BETA_AT_STOP_Y = beta.py_func(STOP_Y)  # the limits' potential (per stiffness) at STOP_Y


@kernel(inline="always")
def fold_stiffness(ea, rest_len, energy):
    """``k_f = max(2 u_on EA l0, K_0 / beta(STOP_Y))`` (J) for start energy ``K_0 = energy`` (J)."""
    return max(2.0 * FOLD_U * ea * rest_len, energy / BETA_AT_STOP_Y)


@kernel(inline="always")
def collapse_stiffness(ea, rest_len, energy):
    """``k_c = max(EA s^2 / l0, K_0 / beta(STOP_Y))`` (J), ``s = COLLAPSE_ON l0``, for start energy
    ``K_0 = energy`` (J)."""
    return max(ea * COLLAPSE_ON * COLLAPSE_ON * rest_len, energy / BETA_AT_STOP_Y)


@kernel(inline="always")
def fold_terms(phi, k):
    """``(E, dE/dphi, d2E/dphi2)`` of the fold limit at turning angle ``phi`` (rad), stiffness ``k``
    (J): zeros while ``|phi| <= FOLD_ON``. ``u = 2 cos^2(phi / 2)`` keeps its digits near the fold."""
    c = math.cos(0.5 * phi)
    y = 2.0 * c * c / FOLD_U
    if y >= 1.0:
        return 0.0, 0.0, 0.0
    s = math.sin(phi)
    slope = beta_slope(y)
    d1 = -k * slope * s / FOLD_U
    d2 = k * (beta_curvature(y) * s * s / (FOLD_U * FOLD_U) - slope * math.cos(phi) / FOLD_U)
    return k * beta(y), d1, d2


@kernel
def wall_limit_energy(x, rest_len, ea, energy):
    """Energy (J) of both limits of a ring with nodes ``x`` (N, 2) m, rest edge length ``rest_len``
    (m), ``EA = ea`` (N) and start energy ``K_0 = energy`` (J): 0 unless a node folds beyond
    ``FOLD_ON`` or an edge is shorter than ``COLLAPSE_ON l0``; inf at a limit."""
    n = x.shape[0]
    kf = fold_stiffness(ea, rest_len, energy)
    kc = collapse_stiffness(ea, rest_len, energy)
    s2 = (COLLAPSE_ON * rest_len) ** 2
    total = 0.0
    for i in range(n):
        e1x, e1y, e2x, e2y = _edges(x, i, n)
        if e1x * e2x + e1y * e2y < 0.0:  # turned beyond 90 degrees: the angle is needed
            total += fold_terms(turning_of(e1x, e1y, e2x, e2y), kf)[0]
        length2 = e2x * e2x + e2y * e2y
        if length2 < s2:
            total += kc * beta(length2 / s2)
    return total


@kernel
def wall_limit_force(x, rest_len, ea, energy, f):
    """Add ``-grad (E_f + E_c)`` (N) at nodes ``x`` (N, 2) m to ``f``; a node folded shut or an edge
    of zero length adds inf."""
    n = x.shape[0]
    kf = fold_stiffness(ea, rest_len, energy)
    kc = collapse_stiffness(ea, rest_len, energy)
    s2 = (COLLAPSE_ON * rest_len) ** 2
    for i in range(n):
        e1x, e1y, e2x, e2y = _edges(x, i, n)
        q = next_node(i, n)
        if e1x * e2x + e1y * e2y < 0.0:
            d1 = fold_terms(turning_of(e1x, e1y, e2x, e2y), kf)[1]
            if d1 != 0.0:
                p = prev_node(i, n)
                g1x, g1y, g2x, g2y = _direction_gradients(e1x, e1y, e2x, e2y)[:4]
                f[p, 0] -= d1 * g1x
                f[p, 1] -= d1 * g1y
                f[i, 0] += d1 * (g1x + g2x)
                f[i, 1] += d1 * (g1y + g2y)
                f[q, 0] -= d1 * g2x
                f[q, 1] -= d1 * g2y
        length2 = e2x * e2x + e2y * e2y
        if length2 < s2:
            if not length2 > 0.0:
                f[i, 0] += math.inf
                continue
            m = 2.0 * kc * beta_slope(length2 / s2) / s2  # dE/d(L^2) times 2
            f[i, 0] += m * e2x
            f[i, 1] += m * e2y
            f[q, 0] -= m * e2x
            f[q, 1] -= m * e2y


@kernel
def wall_limit_jacobian(x, rest_len, ea, energy, coef, band, pos):
    """Add ``coef hess (E_f + E_c)`` at nodes ``x`` (N, 2) m to ``band`` (node blocks by ``pos``; a
    node's blocks reach its neighbours' neighbours, as bending's do)."""
    n = x.shape[0]
    kf = fold_stiffness(ea, rest_len, energy)
    kc = collapse_stiffness(ea, rest_len, energy)
    s2 = (COLLAPSE_ON * rest_len) ** 2
    for i in range(n):
        e1x, e1y, e2x, e2y = _edges(x, i, n)
        q = next_node(i, n)
        if e1x * e2x + e1y * e2y < 0.0:
            _fold_hessian(band, pos, i, n, turning_of(e1x, e1y, e2x, e2y), e1x, e1y, e2x, e2y, kf, coef)
        length2 = e2x * e2x + e2y * e2y
        if length2 < s2 and length2 > 0.0:
            y = length2 / s2
            a = coef * kc * 4.0 * beta_curvature(y) / (s2 * s2)  # times e e^T
            b = coef * kc * 2.0 * beta_slope(y) / s2  # times I
            h00 = a * e2x * e2x + b
            h01 = a * e2x * e2y
            h11 = a * e2y * e2y + b
            band_add_block(band, pos, i, i, h00, h01, h01, h11)
            band_add_block(band, pos, q, q, h00, h01, h01, h11)
            band_add_block(band, pos, i, q, -h00, -h01, -h01, -h11)
            band_add_block(band, pos, q, i, -h00, -h01, -h01, -h11)


@kernel
def _fold_hessian(band, pos, i, n, phi, e1x, e1y, e2x, e2y, kf, coef):
    """Add ``coef (E'' grad phi grad phi^T + E' hess phi)`` of node ``i``'s fold limit (blocks of
    ``hess phi`` as in :func:`effects.bending.bend_jacobian`)."""
    d1, d2 = fold_terms(phi, kf)[1:]
    if d1 == 0.0 and d2 == 0.0:
        return
    add_turning_blocks(band, pos, i, n, e1x, e1y, e2x, e2y, _block, coef * d2, coef * d1)


@kernel(inline="always")
def _block(band, pos, a, b, c2, c1, gax, gay, gbx, gby, ha, hb):
    """Add ``c2 g_a g_b^T + c1 [[ha, hb], [hb, -ha]]`` at node block (a, b)."""
    band_add_block(
        band, pos, a, b,
        c2 * gax * gbx + c1 * ha, c2 * gax * gby + c1 * hb,
        c2 * gay * gbx + c1 * hb, c2 * gay * gby - c1 * ha,
    )  # fmt: skip


# ---------------------------------------------------------------------- continuous detection
@kernel(inline="always")
def _fold_time(e1x, e1y, d1x, d1y, e2x, e2y, d2x, d2y):
    """First time in [0, 1] at which edges ``e1 + t d1`` and ``e2 + t d2`` are antiparallel (their
    cross product, a quadratic in ``t``, vanishes with a negative dot product); inf if never."""
    c0 = e1x * e2y - e1y * e2x
    c1 = e1x * d2y - e1y * d2x + d1x * e2y - d1y * e2x
    c2 = d1x * d2y - d1y * d2x
    first, second = _smallest_root(c0, c1, c2)
    for t in (first, second):
        if t < math.inf:
            ax, ay = e1x + t * d1x, e1y + t * d1y
            bx, by = e2x + t * d2x, e2y + t * d2y
            if ax * bx + ay * by < 0.0:
                return t
    return math.inf


@kernel(inline="always")
def _shrink_time(ex, ey, dx, dy):
    """First time in [0, 1] at which the edge ``e + t d`` is ``SHRINK_FLOOR`` of ``|e|`` long; inf
    if never."""
    a = ex * ex + ey * ey
    b = ex * dx + ey * dy
    c = dx * dx + dy * dy
    if b >= 0.0:
        return math.inf  # the edge does not shrink at first, and |e + t d|^2 is convex
    return _smallest_root(a * (1.0 - SHRINK_FLOOR * SHRINK_FLOOR), 2.0 * b, c)[0]


@kernel
def limit_fraction(xa, xb):
    """The fraction of the straight motion ``xa -> xb`` (N, 2) m to take so that it neither folds a
    node through (two edges antiparallel) nor shrinks an edge below ``SHRINK_FLOOR`` of its length:
    1 if it does neither, else ``CCD_SAFETY`` times the first time it would."""
    n = xa.shape[0]
    first = math.inf
    for i in range(n):
        p = prev_node(i, n)
        q = next_node(i, n)
        e1x, e1y = xa[i, 0] - xa[p, 0], xa[i, 1] - xa[p, 1]
        e2x, e2y = xa[q, 0] - xa[i, 0], xa[q, 1] - xa[i, 1]
        d1x = xb[i, 0] - xb[p, 0] - e1x
        d1y = xb[i, 1] - xb[p, 1] - e1y
        d2x = xb[q, 0] - xb[i, 0] - e2x
        d2y = xb[q, 1] - xb[i, 1] - e2y
        first = min(first, _fold_time(e1x, e1y, d1x, d1y, e2x, e2y, d2x, d2y))
        first = min(first, _shrink_time(e2x, e2y, d2x, d2y))
    return CCD_SAFETY * first if first <= 1.0 else 1.0
