"""Coulomb friction of the grounds, lagged and smoothed as in Incremental Potential Contact
(Li et al. 2020), inside a step of size ``h`` (s) from positions ``x0`` (m).

A vertex i pressed on ground g by the normal force ``lambda_ig`` (N, taken at the step's start and
held through it) slides on it by ``u = T (x_i - x0_i) - s_g``, ``T = I - n n^T`` (m, in the ground's
plane), ``s_g = h T u_g`` the slide of a moving ground's surface over the step (``slide``, m;
touch/motion.py; 0 on a fixed ground).
Friction is the potential (J)::

    D = mu lambda f0(|u|),   f0(y) = -y^3 / (3 e^2) + y^2 / e + e / 3 (y < e),   y (y >= e)

with ``e = eps_v h`` (m; ``eps_v`` the slip speed, m/s, below which friction is smoothed). Its
force ``-grad D = -mu lambda f1(y) u / y``, ``f1 = f0' = 2 y / e - y^2 / e^2`` (y < e), 1 beyond, is
Coulomb's ``mu lambda`` against the slip above ``eps_v`` and proportional to the slip below;
``Hess D = mu lambda [f1 / y T + (f1' - f1 / y) / y^2 u u^T]`` is positive semi-definite
(``f1' - f1 / y = -y / e^2`` below ``e``, ``-1 / y`` above). On a moving surface the force does the
work ``-grad D . s_g`` (J) through the surface's slide (:func:`friction_work`).
"""

import math

from ...physics.base.jit import kernel


@kernel(inline="always")
def slip(x, x0, normals, slide, i, g, u):
    """``u = T (x_i - x0_i) - s_g`` into ``u`` (3,); returns ``|u|`` (m)."""
    dn = 0.0
    for a in range(3):
        dn += normals[g, a] * (x[i, a] - x0[i, a])
    s = 0.0
    for a in range(3):
        u[a] = x[i, a] - x0[i, a] - dn * normals[g, a] - slide[g, a]
        s += u[a] * u[a]
    return math.sqrt(s)


@kernel(inline="always")
def smoothed(y, e):
    """``f0(y)`` (m) of the module doc for a slip ``y`` (m) and smoothing ``e`` (m)."""
    return -y * y * y / (3.0 * e * e) + y * y / e + e / 3.0 if y < e else y


@kernel(inline="always")
def slope_over_slip(y, e):
    """``f1(y) / y`` (1/m) of the module doc."""
    return (2.0 / e - y / (e * e)) if y < e else 1.0 / y


@kernel(inline="always")
def add_vertex(grad, blocks, i, w, y, e, u, n):
    """Adds the gradient ``w f1 u / y`` (N) and Hessian (N/m) of ``w f0(|u|)`` (``w = mu lambda`` N,
    ``u`` (3,) the slip m, ``y = |u|``, ``n`` (3,) the surface's unit normal) to vertex ``i``'s
    entries of ``grad`` (V, 3) and ``blocks`` (V, 3, 3) (module doc)."""
    if y < e:
        f1_y, uu = 2.0 / e - y / (e * e), -1.0 / (y * e * e) if y > 0.0 else 0.0
    else:
        f1_y, uu = 1.0 / y, -1.0 / (y * y * y)
    for a in range(3):
        grad[i, a] += w * f1_y * u[a]
        for b in range(3):
            t_ab = (1.0 if a == b else 0.0) - n[a] * n[b]
            blocks[i, a, b] += w * (f1_y * t_ab + uu * u[a] * u[b])


@kernel
def friction_energy(x, x0, normals, slide, lam, mu, e, u):
    """``sum D`` (J) over the vertex-ground pairs with ``lam[i, g] > 0``; ``u`` (3,) scratch."""
    total = 0.0
    for g in range(normals.shape[0]):
        if mu[g] == 0.0:
            continue
        for i in range(x.shape[0]):
            if lam[i, g] > 0.0:
                y = slip(x, x0, normals, slide, i, g, u)
                total += mu[g] * lam[i, g] * smoothed(y, e)
    return total


@kernel
def add_friction(x, x0, normals, slide, lam, mu, e, grad, blocks, u):
    """Adds ``grad D`` (N) to ``grad`` (V, 3) and ``Hess D`` (N/m) to ``blocks`` (V, 3, 3)."""
    for g in range(normals.shape[0]):
        if mu[g] == 0.0:
            continue
        for i in range(x.shape[0]):
            if lam[i, g] <= 0.0:
                continue
            y = slip(x, x0, normals, slide, i, g, u)
            add_vertex(grad, blocks, i, mu[g] * lam[i, g], y, e, u, normals[g])


@kernel
def friction_work(x, x0, normals, slide, lam, mu, e, u):
    """``sum_ig -grad D_ig . s_g`` (J): the work of friction's force at ``x`` through the grounds'
    slides ``s_g`` (``slide``, (G, 3) m) over the step; 0 on fixed grounds."""
    total = 0.0
    for g in range(normals.shape[0]):
        if mu[g] == 0.0 or (slide[g, 0] == 0.0 and slide[g, 1] == 0.0 and slide[g, 2] == 0.0):
            continue
        for i in range(x.shape[0]):
            if lam[i, g] <= 0.0:
                continue
            y = slip(x, x0, normals, slide, i, g, u)
            f1_y = slope_over_slip(y, e)
            for a in range(3):
                total -= mu[g] * lam[i, g] * f1_y * u[a] * slide[g, a]
    return total
