"""Stretching of the ring's wall: edges as axial springs of stiffness EA (N).

Per edge ``e_i = x_{i+1} - x_i`` of rest length ``l0``::

    E_s = 1/2 EA eps^2 l0,   eps = |e| / l0 - 1                                        [J]

``EA = E b h`` (N). Force ``F = -dE_s/dx`` (N); the Jacobian ``dF/dx`` (N/m) is block tridiagonal,
exact. Always on.
"""

import math
from typing import TYPE_CHECKING

from ..base.cyclic import next_node
from ..base.jit import kernel
from ..base.linalg import band_add_block

if TYPE_CHECKING:
    from ..scene import Scene

NAME = "stretching"
ENERGY_PART = "stretching"
LOW_RANK = 0
PARAMETERS = ()


def enabled(scene: "Scene") -> bool:
    """Every ring stretches."""
    return True


@kernel(inline="always")
def on(model, p, r):
    return True


@kernel(inline="always")
def force(model, p, r, x, v, f):
    """Add the stretching forces (N) on ring ``r`` to ``f``."""
    stretch_force(x, model.rest_len[r], model.ea[r], f)


@kernel(inline="always")
def jacobian(model, p, r, x, v, coef_x, coef_v, ws, rank):
    """Add ``coef_x dF/dx`` to ``ws.band`` (no velocity dependence, no low-rank part)."""
    stretch_jacobian(x, model.rest_len[r], model.ea[r], coef_x, ws.band, ws.pos)
    return rank


@kernel(inline="always")
def energy(model, p, r, x, v):
    """Stretching energy (J) of ring ``r``."""
    return stretch_energy(x, model.rest_len[r], model.ea[r])


@kernel
def _edge(x, i, n, rest_len):
    """Edge ``(i, i + 1)``: its end node ``j``, vector ``(dx, dy)`` and length (m), and strain
    ``eps = |e| / l0 - 1``."""
    j = next_node(i, n)
    dx = x[j, 0] - x[i, 0]
    dy = x[j, 1] - x[i, 1]
    length = math.sqrt(dx * dx + dy * dy)
    return j, dx, dy, length, length / rest_len - 1.0


@kernel
def stretch_energy(x, rest_len, ea):
    """Stretching energy (J) of the ring."""
    n = x.shape[0]
    e = 0.0
    for i in range(n):
        eps = _edge(x, i, n, rest_len)[4]
        e += 0.5 * ea * eps * eps * rest_len
    return e


@kernel
def stretch_force(x, rest_len, ea, f):
    """Add the stretching forces (N) to ``f`` (N, 2)."""
    n = x.shape[0]
    for i in range(n):
        j, dx, dy, length, eps = _edge(x, i, n, rest_len)
        s = ea * eps / length
        f[i, 0] += s * dx
        f[i, 1] += s * dy
        f[j, 0] -= s * dx
        f[j, 1] -= s * dy


@kernel
def stretch_jacobian(x, rest_len, ea, coef, band, pos):
    """Add ``coef * dF_s/dx`` to ``band``.

    With ``u = e/|e|``, the Hessian of ``E_s`` in ``e`` is ``H = EA [u u^T / l0 + eps (I - u u^T)/|e|]``;
    ``dF_i/dx_i = dF_j/dx_j = -H`` and ``dF_i/dx_j = dF_j/dx_i = H``.
    """
    n = x.shape[0]
    for i in range(n):
        j, dx, dy, length, eps = _edge(x, i, n, rest_len)
        ux = dx / length
        uy = dy / length
        a = ea / rest_len
        b = ea * eps / length
        h00 = coef * (a * ux * ux + b * (1.0 - ux * ux))
        h01 = coef * (a * ux * uy - b * ux * uy)
        h11 = coef * (a * uy * uy + b * (1.0 - uy * uy))
        band_add_block(band, pos, i, i, -h00, -h01, -h01, -h11)
        band_add_block(band, pos, j, j, -h00, -h01, -h01, -h11)
        band_add_block(band, pos, i, j, h00, h01, h01, h11)
        band_add_block(band, pos, j, i, h00, h01, h01, h11)
