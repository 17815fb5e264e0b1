"""Gas pressure: the gas law inside the ring's polygon, a potential.

The ring holds an amount of gas with ``(p + p_atm) A^k = C`` (``C`` = ``Model.gas_constant``,
Pa m^(2k); ``k`` = ``Model.gas_exponent``, 1 isothermal, 1.4 adiabatic; ``p_atm`` Pa): gauge
pressure ``p`` (Pa) at polygon area ``A`` (m^2). The gauge pressure may be negative (an
under-inflated ball, a ring under external pressure) as long as the absolute pressure ``p + p_atm``
is positive. ``k = 0`` is a regulated pressure: ``p = C - p_atm`` whatever the area, no gas
stiffness (``dp/dA = 0``), potential ``U = -b p A``. Its line load ``p b`` on each edge is, exactly,
``F_i = p b dA/dx_i`` (N), the gradient of the potential ``U = -b int p dA`` (J). The Jacobian
``b (p hess A + dp/dA grad A grad A^T)`` is a band part plus one low-rank column (kept exact, solved
in O(N) by the Woodbury identity). On for rings with ``Ring.pressure`` set.
"""

import math
from typing import TYPE_CHECKING

from ..base.cyclic import next_node, prev_node
from ..base.geometry import polygon_area
from ..base.jit import kernel
from ..base.linalg import band_add_block

if TYPE_CHECKING:
    from ..scene import Scene

NAME = "pressure"
ENERGY_PART = "gas"
LOW_RANK = 1
PARAMETERS = ()


def enabled(scene: "Scene") -> bool:
    """Any ring holds gas."""
    return any(r.pressure is not None for r in scene.rings)


@kernel(inline="always")
def on(model, p, r):
    return model.pressurised[r]


@kernel
def ring_pressure(model, r, x):
    """Gauge pressure (Pa) of ring ``r`` with nodes ``x``; 0 for a ring without gas."""
    if not model.pressurised[r]:
        return 0.0
    return gas_pressure(
        polygon_area(x), model.gas_constant[r], model.gas_exponent, model.atmospheric_pressure
    )


@kernel(inline="always")
def force(model, p, r, x, v, f):
    """Add ``F_i = p b dA/dx_i`` (N) of ring ``r`` to ``f``."""
    pressure_force(x, ring_pressure(model, r, x), model.width[r], f)


@kernel(inline="always")
def jacobian(model, p, r, x, v, coef_x, coef_v, ws, rank):
    """Add ``coef_x dF/dx`` to ``ws.band`` and its rank-one part to ``ws.u``, ``ws.w``."""
    area = polygon_area(x)
    pressure = gas_pressure(area, model.gas_constant[r], model.gas_exponent, model.atmospheric_pressure)
    slope = gas_pressure_slope(area, model.gas_constant[r], model.gas_exponent)
    return pressure_jacobian(x, pressure, slope, model.width[r], coef_x, ws.band, ws.pos, ws.u, ws.w, rank)


@kernel(inline="always")
def energy(model, p, r, x, v):
    """Potential (J) of ring ``r``'s gas (see :func:`gas_energy`)."""
    return gas_energy(
        polygon_area(x), model.gas_constant[r], model.gas_exponent, model.atmospheric_pressure,
        model.width[r],
    )  # fmt: skip


@kernel
def gas_pressure(area, gas_constant, gas_exponent, atmospheric_pressure):
    """Gauge pressure (Pa) from the gas law ``(p + p_atm) A^k = C``; ``C`` in Pa m^(2k). NaN for a
    polygon turned inside out (``A <= 0``: no gas state; the Newton iterate is then taken back or
    the step rejected)."""
    if not area > 0.0:
        return math.nan
    return gas_constant / area**gas_exponent - atmospheric_pressure


@kernel
def gas_pressure_slope(area, gas_constant, gas_exponent):
    """``dp/dA = -k (p + p_atm) / A`` (Pa/m^2); NaN for ``A <= 0``."""
    if not area > 0.0:
        return math.nan
    return -gas_exponent * gas_constant / area ** (gas_exponent + 1.0)


@kernel
def gas_energy(area, gas_constant, gas_exponent, atmospheric_pressure, width):
    """Potential (J) of the gas, ``U = -b int (p + p_atm - p_atm) dA``; ``F = -dU/dx = b p dA/dx``.

    ``k = 1``: ``U = -b (C ln A - p_atm A)``; otherwise ``U = -b (C A^(1-k) / (1-k) - p_atm A)``.
    NaN for ``A <= 0``.
    """
    if not area > 0.0:
        return math.nan
    if gas_exponent == 1.0:
        return -width * (gas_constant * math.log(area) - atmospheric_pressure * area)
    return -width * (
        gas_constant * area ** (1.0 - gas_exponent) / (1.0 - gas_exponent) - atmospheric_pressure * area
    )


@kernel
def pressure_force(x, pressure, width, f):
    """Add ``F_i = p b dA/dx_i`` (the line load ``p b`` along each edge, half to each end node)."""
    n = x.shape[0]
    s = 0.5 * pressure * width
    for i in range(n):
        p = prev_node(i, n)
        q = next_node(i, n)
        f[i, 0] += s * (x[q, 1] - x[p, 1])
        f[i, 1] += s * (x[p, 0] - x[q, 0])


@kernel
def pressure_jacobian(x, pressure, pressure_slope, width, coef, band, pos, u, w, rank):
    """Add ``coef dF/dx = coef b (p hess A + dp/dA grad A grad A^T)``; the second term is rank one."""
    n = x.shape[0]
    s = 0.5 * coef * pressure * width
    for i in range(n):
        q = next_node(i, n)
        # d(grad_i A)/dx_{i+1} = [[0, 1/2], [-1/2, 0]], d(grad_{i+1} A)/dx_i is its transpose
        band_add_block(band, pos, i, q, 0.0, s, -s, 0.0)
        band_add_block(band, pos, q, i, 0.0, -s, s, 0.0)
    r = coef * width * pressure_slope
    for i in range(n):
        p = prev_node(i, n)
        q = next_node(i, n)
        gx = 0.5 * (x[q, 1] - x[p, 1])
        gy = 0.5 * (x[p, 0] - x[q, 0])
        u[2 * i, rank] = gx
        u[2 * i + 1, rank] = gy
        w[2 * i, rank] = r * gx
        w[2 * i + 1, rank] = r * gy
    return rank + 1
