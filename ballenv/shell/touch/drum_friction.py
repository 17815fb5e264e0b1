"""Coulomb friction of the drums (drum.py), lagged and smoothed as the grounds' (friction.py), inside
a step of ``h`` (s) from positions ``x0`` (m), on the slip relative to the turning surface.

A vertex i pressed on drum k by the normal force ``lambda_ik`` (N, taken at the step's start and
held through it) slides on it by (m)::

    u = T (x_i - x0_i) - s_ik,      T = I - e e^T,      s_ik = theta_k a_k x (x0_i - c_k)

``e`` the radial direction (drum.py) at ``x0_i``, held through the step as ``lambda`` is, and
``s_ik`` the surface's slide under the vertex over the step: ``theta_k = int Omega_k dt`` (rad,
turning.py) is the angle the drum turns in it, so ``s_ik = h w(x0_i, t_mid)`` for the surface's
velocity ``w = Omega a x (x - c)`` at the step's middle wherever ``Omega`` is linear in the step.
``s_ik`` is tangential (normal to ``e`` and ``a``), so ``T s_ik = s_ik``. The potential, force and
Hessian are friction.py's, with the vertex's own ``T`` and ``s``::

    D = mu lambda f0(|u|),    -grad D = -mu lambda f1(y) u / y,
    Hess D = mu lambda [f1 / y T + (f1' - f1 / y) / y^2 u u^T]      (J, N, N/m)

The force does the work ``-grad D . s_ik`` (J) through the surface's slide (:func:`friction_work`).
"""

import math

from ...physics.base.jit import kernel
from .drum import perpendicular
from .friction import add_vertex, slope_over_slip, smoothed


@kernel(inline="always")
def _slip(x, x0, drums, i, k):
    """The radial direction, the slide and the slip ``u`` into ``drums.scratch`` rows 0, 1, 2; returns
    ``|u|`` (m)."""
    e, s, u = drums.scratch[0], drums.scratch[1], drums.scratch[2]
    e[0], e[1], e[2] = perpendicular(x0, i, drums, k, 1.0)
    rho = math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])
    for c in range(3):
        e[c] /= rho
    a, theta = drums.axis, drums.turn[k]
    s[0] = theta * (a[k, 1] * e[2] - a[k, 2] * e[1]) * rho
    s[1] = theta * (a[k, 2] * e[0] - a[k, 0] * e[2]) * rho
    s[2] = theta * (a[k, 0] * e[1] - a[k, 1] * e[0]) * rho
    dn = 0.0
    for c in range(3):
        dn += e[c] * (x[i, c] - x0[i, c])
    size = 0.0
    for c in range(3):
        u[c] = x[i, c] - x0[i, c] - dn * e[c] - s[c]
        size += u[c] * u[c]
    return math.sqrt(size)


@kernel
def friction_energy(x, x0, drums, e):
    """``sum D`` (J) over the vertex-drum pairs with ``lam[i, k] > 0``; ``e = eps_v h`` (m)."""
    total = 0.0
    for k in range(drums.mu.shape[0]):
        if drums.mu[k] == 0.0:
            continue
        for i in range(x.shape[0]):
            if drums.lam[i, k] > 0.0:
                y = _slip(x, x0, drums, i, k)
                total += drums.mu[k] * drums.lam[i, k] * smoothed(y, e)
    return total


@kernel
def add_friction(x, x0, drums, e, grad, blocks):
    """Adds ``grad D`` (N) to ``grad`` (V, 3) and ``Hess D`` (N/m) to ``blocks`` (V, 3, 3)."""
    n, u = drums.scratch[0], drums.scratch[2]
    for k in range(drums.mu.shape[0]):
        if drums.mu[k] == 0.0:
            continue
        for i in range(x.shape[0]):
            if drums.lam[i, k] <= 0.0:
                continue
            y = _slip(x, x0, drums, i, k)
            add_vertex(grad, blocks, i, drums.mu[k] * drums.lam[i, k], y, e, u, n)


@kernel
def friction_work(x, x0, drums, e):
    """``sum_ik -grad D_ik . s_ik`` (J): the work of friction's force at ``x`` through the drums'
    surfaces' slides over the step; 0 on fixed drums."""
    total = 0.0
    s, u = drums.scratch[1], drums.scratch[2]
    for k in range(drums.mu.shape[0]):
        if drums.mu[k] == 0.0 or drums.turn[k] == 0.0:
            continue
        for i in range(x.shape[0]):
            if drums.lam[i, k] <= 0.0:
                continue
            y = _slip(x, x0, drums, i, k)
            f1_y = slope_over_slip(y, e)
            for a in range(3):
                total -= drums.mu[k] * drums.lam[i, k] * f1_y * u[a] * s[a]
    return total
