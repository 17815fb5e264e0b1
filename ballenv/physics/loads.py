"""External and dissipative loads on a ring: pressure (gas law), gravity, damping. One effect each.

All kernels work on one ring: nodes ``x`` (N, 2) m, velocities ``v`` (N, 2) m/s, equal node mass
``m`` (kg). Force kernels add into ``f`` (N, 2) in newtons. Jacobian kernels add
``coef_x * dF/dx + coef_v * dF/dv`` into a band matrix and append their low-rank part as columns of
``u``, ``w`` (the matrix gets ``+ u w^T``); they return the new rank.
"""

import math

from numba import njit

from .cyclic import next_node, prev_node
from .linalg import band_add_block

DAMPING_NONE = 0
DAMPING_RIGID = 1
DAMPING_CENTRE_OF_MASS = 2


# ----------------------------------------------------------------------------------------- pressure
@njit(cache=True)
def polygon_area(x):
    """Shoelace area (m^2) of the ring's polygon; positive for counter-clockwise nodes."""
    n = x.shape[0]
    a = 0.0
    for i in range(n):
        j = next_node(i, n)
        a += x[i, 0] * x[j, 1] - x[j, 0] * x[i, 1]
    return 0.5 * a


@njit(cache=True)
def gas_pressure(area, gas_constant, gas_exponent, atmospheric_pressure):
    """Gauge pressure (Pa) from the gas law ``(p + p_atm) A^k = C``; ``C`` in Pa m^(2k). NaN for a
    polygon turned inside out (``A <= 0``: no gas state; the Newton iterate is then taken back or
    the step rejected)."""
    if not area > 0.0:
        return math.nan
    return gas_constant / area**gas_exponent - atmospheric_pressure


@njit(cache=True)
def gas_pressure_slope(area, gas_constant, gas_exponent):
    """``dp/dA = -k (p + p_atm) / A`` (Pa/m^2); NaN for ``A <= 0``."""
    if not area > 0.0:
        return math.nan
    return -gas_exponent * gas_constant / area ** (gas_exponent + 1.0)


@njit(cache=True)
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


@njit(cache=True)
def pressure_force(x, pressure, width, f):
    """Add ``F_i = p b dA/dx_i`` (the line load ``p b`` along each edge, half to each end node)."""
    n = x.shape[0]
    s = 0.5 * pressure * width
    for i in range(n):
        p = prev_node(i, n)
        q = next_node(i, n)
        f[i, 0] += s * (x[q, 1] - x[p, 1])
        f[i, 1] += s * (x[p, 0] - x[q, 0])


@njit(cache=True)
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


# ------------------------------------------------------------------------------------------ gravity
@njit(cache=True)
def gravity_force(node_mass, gravity, f):
    """Add ``F_i = m g`` with ``gravity`` the acceleration vector (m/s^2)."""
    for i in range(f.shape[0]):
        f[i, 0] += node_mass * gravity[0]
        f[i, 1] += node_mass * gravity[1]


@njit(cache=True)
def gravity_energy(x, node_mass, gravity):
    """Potential (J) ``-sum_i m g . x_i``."""
    e = 0.0
    for i in range(x.shape[0]):
        e -= node_mass * (gravity[0] * x[i, 0] + gravity[1] * x[i, 1])
    return e


# ------------------------------------------------------------------------------------------ damping
@njit(cache=True)
def centre_of_mass(x, v):
    """Centre of mass (m) and its velocity (m/s) of nodes of equal mass: ``(cx, cy, vx, vy)``."""
    n = x.shape[0]
    cx = cy = vx = vy = 0.0
    for i in range(n):
        cx += x[i, 0]
        cy += x[i, 1]
        vx += v[i, 0]
        vy += v[i, 1]
    return cx / n, cy / n, vx / n, vy / n


@njit(cache=True)
def rigid_motion(x, v):
    """Centre of mass (m), its velocity (m/s), spin ``omega`` (rad/s) and ``sum |r|^2`` (m^2).

    For equal node masses: ``omega = sum r_i x u_i / sum |r_i|^2`` with ``r_i = x_i - X``.
    """
    n = x.shape[0]
    cx, cy, vx, vy = centre_of_mass(x, v)
    ang = 0.0
    inertia = 0.0
    for i in range(n):
        rx = x[i, 0] - cx
        ry = x[i, 1] - cy
        ang += rx * v[i, 1] - ry * v[i, 0]
        inertia += rx * rx + ry * ry
    return cx, cy, vx, vy, ang / inertia, inertia


@njit(cache=True)
def damping_force(x, v, node_mass, damping, mode, f):
    """Add ``F_i = -c m (u_i - u_rigid,i)``; ``u_rigid = V + omega e_z x r_i`` (mode rigid) or ``V``
    (mode centre of mass, the paper's, which also damps spin). ``c`` in 1/s."""
    cx, cy, vx, vy, omega, _ = rigid_motion(x, v)
    if mode == DAMPING_CENTRE_OF_MASS:
        omega = 0.0
    cm = damping * node_mass
    for i in range(x.shape[0]):
        rx = x[i, 0] - cx
        ry = x[i, 1] - cy
        f[i, 0] -= cm * (v[i, 0] - vx + omega * ry)
        f[i, 1] -= cm * (v[i, 1] - vy - omega * rx)


@njit(cache=True)
def damping_jacobian(x, v, node_mass, damping, mode, coef_x, coef_v, band, pos, u, w, rank):
    """Add ``coef_x dF/dx + coef_v dF/dv`` of the damping force.

    ``dF_i/du_j = -c m d_ij I + c m^2 / M I + c m^2 r_i^perp r_j^perp^T / I_r`` (rank 3 beyond the
    diagonal; the last term only in mode rigid). In mode rigid the spin depends on positions:
    ``dF_i/dx_j = c m [omega R d_ij - omega R m / M + r_i^perp (d omega / dx_j)^T]``, with
    ``R`` the quarter turn, ``d omega/dx_j = m (R^T (u_j - V) - 2 omega r_j) / I_r`` and
    ``I_r = m sum |r|^2``.
    """
    n = x.shape[0]
    cx, cy, vx, vy, omega, sum_r2 = rigid_motion(x, v)
    c = damping
    m = node_mass
    total_mass = n * m
    rigid = mode == DAMPING_RIGID
    diag = -coef_v * c * m
    spin = coef_x * c * m * omega if rigid else 0.0
    for i in range(n):
        band_add_block(band, pos, i, i, diag, -spin, spin, diag)
    for i in range(n):
        u[2 * i, rank] = m
        u[2 * i + 1, rank] = 0.0
        u[2 * i, rank + 1] = 0.0
        u[2 * i + 1, rank + 1] = m
        w[2 * i, rank] = coef_v * c * m / total_mass
        w[2 * i + 1, rank] = (coef_x * c * omega * m / total_mass) if rigid else 0.0
        w[2 * i, rank + 1] = (-coef_x * c * omega * m / total_mass) if rigid else 0.0
        w[2 * i + 1, rank + 1] = coef_v * c * m / total_mass
    if not rigid:
        return rank + 2
    inertia = m * sum_r2
    for i in range(n):
        rx = x[i, 0] - cx
        ry = x[i, 1] - cy
        u[2 * i, rank + 2] = -m * ry
        u[2 * i + 1, rank + 2] = m * rx
        dux = v[i, 0] - vx
        duy = v[i, 1] - vy
        wx = m * (duy - 2.0 * omega * rx) / inertia
        wy = m * (-dux - 2.0 * omega * ry) / inertia
        w[2 * i, rank + 2] = coef_x * c * wx + coef_v * c * (-m * ry) / inertia
        w[2 * i + 1, rank + 2] = coef_x * c * wy + coef_v * c * (m * rx) / inertia
    return rank + 3
