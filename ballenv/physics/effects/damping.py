"""Damping of the wall's deformation: ``F_i = -c m (u_i - u_rigid,i)`` (N), ``c`` in 1/s.

``u_rigid`` is the ring's rigid-body motion: centre-of-mass velocity plus spin about the centre of
mass (mode rigid), so neither flight nor spin nor rolling is damped, only deformation; or the
centre-of-mass velocity alone (mode centre of mass, the paper's form, which also damps spin). The
coupling through the centre of mass and spin is low-rank (2 or 3 columns). Dissipative: no energy.
On when ``Scene.damping`` is not 0.
"""

from typing import TYPE_CHECKING

from ..base.geometry import rigid_motion
from ..base.jit import kernel
from ..base.linalg import band_add_block

if TYPE_CHECKING:
    from ..scene import Scene

NAME = "damping"
ENERGY_PART = None
LOW_RANK = 3
PARAMETERS = ()

DAMPING_NONE = 0
DAMPING_RIGID = 1
DAMPING_CENTRE_OF_MASS = 2


def enabled(scene: "Scene") -> bool:
    """The scene's damping is not zero."""
    return scene.damping != 0.0


@kernel(inline="always")
def on(model, p, r):
    return model.damping_mode != DAMPING_NONE


@kernel(inline="always")
def force(model, p, r, x, v, f):
    """Add the damping force (N) on ring ``r`` to ``f``."""
    damping_force(x, v, model.node_mass[r], model.damping, model.damping_mode, f)


@kernel(inline="always")
def jacobian(model, p, r, x, v, coef_x, coef_v, ws, rank):
    """Add ``coef_x dF/dx + coef_v dF/dv`` to ``ws.band`` and its low-rank part to ``ws.u``, ``ws.w``."""
    return damping_jacobian(
        x, v, model.node_mass[r], model.damping, model.damping_mode, coef_x, coef_v, ws.band, ws.pos,
        ws.u, ws.w, rank,
    )  # fmt: skip


@kernel(inline="always")
def energy(model, p, r, x, v):
    """Dissipative: no potential."""
    return 0.0


@kernel
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


@kernel
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
