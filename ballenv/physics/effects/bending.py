"""Bending of the ring's wall: a discrete elastic rod's turning angles, stiffness EI (N m^2).

Per node, with the turning angle ``phi_i`` between edges ``e_{i-1}`` and ``e_i``::

    E_b = 1/2 (EI / l0) (phi_i - phi0)^2,   phi0 = 2 pi / N (the circle)                [J]

``EI = E b h^3 / 12`` (N m^2). Force ``F = -dE_b/dx`` (N); the Jacobian couples each node with two
neighbours on each side (band half-width 2 nodes), exact. Always on.
"""

import math
from typing import TYPE_CHECKING

from ..base.cyclic import next_node, prev_node
from ..base.jit import kernel
from ..base.linalg import band_add_block

if TYPE_CHECKING:
    from ..scene import Scene

NAME = "bending"
ENERGY_PART = "bending"
LOW_RANK = 0
PARAMETERS = ()


def enabled(scene: "Scene") -> bool:
    """Every ring bends."""
    return True


@kernel(inline="always")
def on(model, p, r):
    return True


@kernel(inline="always")
def force(model, p, r, x, v, f):
    """Add the bending forces (N) on ring ``r`` to ``f``."""
    bend_force(x, model.rest_len[r], model.ei[r], model.rest_turn[r], f)


@kernel(inline="always")
def jacobian(model, p, r, x, v, coef_x, coef_v, ws, rank):
    """Add ``coef_x dF/dx`` to ``ws.band`` (no velocity dependence, no low-rank part)."""
    bend_jacobian(x, model.rest_len[r], model.ei[r], model.rest_turn[r], coef_x, ws.band, ws.pos)
    return rank


@kernel(inline="always")
def energy(model, p, r, x, v):
    """Bending energy (J) of ring ``r``."""
    return bend_energy(x, model.rest_len[r], model.ei[r], model.rest_turn[r])


@kernel
def _edges(x, i, n):
    """Node ``i``'s edges ``e1 = x_i - x_{i-1}`` and ``e2 = x_{i+1} - x_i`` (m)."""
    p = prev_node(i, n)
    q = next_node(i, n)
    return x[i, 0] - x[p, 0], x[i, 1] - x[p, 1], x[q, 0] - x[i, 0], x[q, 1] - x[i, 1]


@kernel(inline="always")
def turning_of(e1x, e1y, e2x, e2y):
    """Turning angle (rad) from edge ``e1`` to edge ``e2``, in (-pi, pi]."""
    return math.atan2(e1x * e2y - e1y * e2x, e1x * e2x + e1y * e2y)


@kernel
def _turning_angle(x, i, n):
    e1x, e1y, e2x, e2y = _edges(x, i, n)
    return turning_of(e1x, e1y, e2x, e2y), e1x, e1y, e2x, e2y


@kernel
def _direction_gradients(e1x, e1y, e2x, e2y):
    """``g(e1)``, ``g(e2)`` with ``g(e) = (-e_y, e_x) / |e|^2`` (the gradient of the edge's direction
    angle, 1/m), and ``|e1|^2``, ``|e2|^2``."""
    s1 = e1x * e1x + e1y * e1y
    s2 = e2x * e2x + e2y * e2y
    return -e1y / s1, e1x / s1, -e2y / s2, e2x / s2, s1, s2


@kernel
def bend_energy(x, rest_len, ei, rest_turn):
    """Bending energy (J) of the ring."""
    n = x.shape[0]
    k = ei / rest_len
    e = 0.0
    for i in range(n):
        phi = _turning_angle(x, i, n)[0]
        e += 0.5 * k * (phi - rest_turn) ** 2
    return e


@kernel
def bend_force(x, rest_len, ei, rest_turn, f):
    """Add the bending forces (N) to ``f``.

    ``dphi/dx_{i-1} = g(e1)``, ``dphi/dx_i = -g(e1) - g(e2)``, ``dphi/dx_{i+1} = g(e2)`` with
    ``g(e) = (-e_y, e_x) / |e|^2`` the gradient of the edge's direction angle.
    """
    n = x.shape[0]
    k = ei / rest_len
    for i in range(n):
        phi, e1x, e1y, e2x, e2y = _turning_angle(x, i, n)
        g1x, g1y, g2x, g2y = _direction_gradients(e1x, e1y, e2x, e2y)[:4]
        m = -k * (phi - rest_turn)
        p = prev_node(i, n)
        q = next_node(i, n)
        f[p, 0] += m * g1x
        f[p, 1] += m * g1y
        f[i, 0] -= m * (g1x + g2x)
        f[i, 1] -= m * (g1y + g2y)
        f[q, 0] += m * g2x
        f[q, 1] += m * g2y


@kernel
def bend_jacobian(x, rest_len, ei, rest_turn, coef, band, pos):
    """Add ``coef * dF_b/dx = -coef k [grad phi grad phi^T + (phi - phi0) hess phi]`` to ``band``.

    The Hessian of the edge angle is ``H(e) = [[2 ex ey, ey^2 - ex^2], [ey^2 - ex^2, -2 ex ey]] / |e|^4``;
    ``hess phi`` has blocks (prev, prev) = -H1, (prev, i) = H1, (i, i) = H2 - H1, (i, next) = -H2,
    (next, next) = H2.
    """
    n = x.shape[0]
    k = ei / rest_len
    for i in range(n):
        phi, e1x, e1y, e2x, e2y = _turning_angle(x, i, n)
        add_turning_blocks(band, pos, i, n, e1x, e1y, e2x, e2y, _bend_block, -coef * k, phi - rest_turn)


@kernel(inline="always")
def add_turning_blocks(band, pos, i, n, e1x, e1y, e2x, e2y, block, u, w):
    """Add to ``band`` the nine node blocks (a, b), a and b in (prev, i, next), of a function of
    node ``i``'s turning angle (edges ``e1``, ``e2``), each by ``block(band, pos, a, b, u, w, g_a,
    g_b, ha, hb)`` from the gradient blocks ``g_a``, ``g_b`` (:func:`_direction_gradients`) and
    ``hess phi``'s block ``[[ha, hb], [hb, -ha]]`` (module doc of :func:`bend_jacobian`); ``u``,
    ``w``: the two weights ``block`` combines them with."""
    gpx, gpy, gnx, gny, s1, s2 = _direction_gradients(e1x, e1y, e2x, e2y)
    gix, giy = -gpx - gnx, -gpy - gny
    a1 = 2.0 * e1x * e1y / (s1 * s1)
    b1 = (e1y * e1y - e1x * e1x) / (s1 * s1)
    a2 = 2.0 * e2x * e2y / (s2 * s2)
    b2 = (e2y * e2y - e2x * e2x) / (s2 * s2)
    p = prev_node(i, n)
    q = next_node(i, n)
    block(band, pos, p, p, u, w, gpx, gpy, gpx, gpy, -a1, -b1)
    block(band, pos, p, i, u, w, gpx, gpy, gix, giy, a1, b1)
    block(band, pos, i, p, u, w, gix, giy, gpx, gpy, a1, b1)
    block(band, pos, i, i, u, w, gix, giy, gix, giy, a2 - a1, b2 - b1)
    block(band, pos, i, q, u, w, gix, giy, gnx, gny, -a2, -b2)
    block(band, pos, q, i, u, w, gnx, gny, gix, giy, -a2, -b2)
    block(band, pos, q, q, u, w, gnx, gny, gnx, gny, a2, b2)
    block(band, pos, p, q, u, w, gpx, gpy, gnx, gny, 0.0, 0.0)
    block(band, pos, q, p, u, w, gnx, gny, gpx, gpy, 0.0, 0.0)


@kernel
def _bend_block(band, pos, a, b, c, t, gax, gay, gbx, gby, ha, hb):
    """Add ``c (g_a g_b^T + t [[ha, hb], [hb, -ha]])`` at node block (a, b)."""
    band_add_block(
        band,
        pos,
        a,
        b,
        c * (gax * gbx + t * ha),
        c * (gax * gby + t * hb),
        c * (gay * gbx + t * hb),
        c * (gay * gby - t * ha),
    )
