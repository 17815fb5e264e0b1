"""The gas inside a shell: the enclosed volume, the gas law and the gas's potential energy.

The volume (m^3) of a closed, outward-oriented mesh by the divergence theorem::

    V = sum_t x0 . (x1 x x2) / 6,   dV/dx0 = x1 x x2 / 6 (and cyclically),
    d2V/dx0 dx1 = -[x2]x / 6,  d2V/dx0 dx2 = [x1]x / 6,  d2V/dx1 dx2 = -[x0]x / 6

(``[v]x w = v x w``; the diagonal blocks are zero). The gas law ``(p + p_atm) V^gamma = const``
with the gauge pressure ``p0`` (Pa) at the rest volume ``V0`` gives ``p(V) = P0 (V0 / V)^gamma -
p_atm``, ``P0 = p0 + p_atm``; ``gamma = 1`` is isothermal, 1.4 adiabatic, and ``gamma = 0`` a constant
pressure (a gas that adds no stiffness). Its potential, the work the skin does on the gas and the
atmosphere from the rest volume, is::

    U(V) = p_atm (V - V0) - P0 V0 f(V / V0),   f(r) = ln r (gamma = 1),  (r^(1-gamma) - 1) / (1 - gamma)

so that ``dU/dV = -p`` and ``d2U/dV2 = gamma (p + p_atm) / V``. Its Hessian in the vertex positions is
``-p d2V + (gamma (p + p_atm) / V) dV dV^T``: a sparse part and a rank-one part, kept apart.
"""

import numpy as np

from ...physics.base.jit import kernel


@kernel
def volume(x, tri):
    """Enclosed volume (m^3) of the mesh ``x`` (V, 3) with outward triangles ``tri`` (T, 3)."""
    total = 0.0
    for t in range(tri.shape[0]):
        p, q, r = x[tri[t, 0]], x[tri[t, 1]], x[tri[t, 2]]
        total += (
            p[0] * (q[1] * r[2] - q[2] * r[1])
            + p[1] * (q[2] * r[0] - q[0] * r[2])
            + p[2] * (q[0] * r[1] - q[1] * r[0])
        )
    return total / 6.0


@kernel
def volume_gradient(x, tri, out):
    """``dV/dx`` (m^2) into ``out`` (V, 3) (overwritten)."""
    out[:] = 0.0
    for t in range(tri.shape[0]):
        for m in range(3):
            i, j, k = tri[t, m], tri[t, (m + 1) % 3], tri[t, (m + 2) % 3]
            q, r = x[j], x[k]
            out[i, 0] += (q[1] * r[2] - q[2] * r[1]) / 6.0
            out[i, 1] += (q[2] * r[0] - q[0] * r[2]) / 6.0
            out[i, 2] += (q[0] * r[1] - q[1] * r[0]) / 6.0


@kernel
def add_volume_hessians(x, tri, scale, out):
    """Adds ``scale`` times each triangle's ``d2V`` (9 x 9, m) to ``out`` (T, 9, 9)."""
    s = scale / 6.0
    for t in range(tri.shape[0]):
        for m in range(3):
            a, b = m, (m + 1) % 3
            v = x[tri[t, (m + 2) % 3]]  # d2V/dx_a dx_b = -[x_c]x / 6 for (a, b, c) cyclic
            for i in range(3):
                for j in range(3):
                    if i == j:
                        continue
                    k = 3 - i - j
                    sign = 1.0 if (j - i) % 3 == 1 else -1.0
                    entry = s * sign * v[k]  # -[v]x_ij = sign v_k
                    out[t, 3 * a + i, 3 * b + j] += entry
                    out[t, 3 * b + j, 3 * a + i] += entry


@kernel
def gauge_pressure(model, vol):
    """Gauge pressure p (Pa) of the gas at volume ``vol`` (m^3)."""
    return (
        model.absolute_pressure[0] * (model.rest_volume / vol) ** model.gas_exponent
        - model.atmospheric_pressure
    )


@kernel
def gas_energy(model, vol):
    """Potential U (J) of the gas and atmosphere at volume ``vol`` (m^3), zero at the rest volume."""
    v0, gamma = model.rest_volume, model.gas_exponent
    log_r = np.log(vol / v0)
    if abs(1.0 - gamma) < 1e-12:
        f = log_r
    else:
        f = np.expm1((1.0 - gamma) * log_r) / (1.0 - gamma)
    return model.atmospheric_pressure * (vol - v0) - model.absolute_pressure[0] * v0 * f


@kernel
def gas_stiffness(model, vol):
    """``d2U/dV2 = gamma (p + p_atm) / V`` (Pa/m^3): the weight of the rank-one term ``dV dV^T``."""
    return model.gas_exponent * (gauge_pressure(model, vol) + model.atmospheric_pressure) / vol
