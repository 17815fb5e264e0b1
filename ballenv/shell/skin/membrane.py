"""Membrane stretching of a shell: constant-strain triangles of a St. Venant-Kirchhoff material in
plane stress.

Each triangle's rest shape gives three vectors ``beta_a`` in R^2 (``beta_0 = -beta_1 - beta_2``, the
rows of the inverse of the rest edge matrix in a frame of the rest plane), so that the deformation
gradient is ``F = sum_a x_a beta_a^T`` (3 x 2) and the Green strain ``G = (F^T F - I) / 2``. The
energy of a triangle of rest area ``A`` (m^2) and thickness ``h`` (m) is::

    W = A h [ lam / 2 tr(G)^2 + mu tr(G^2) ],   lam = E nu / (1 - nu^2),  mu = E / (2 (1 + nu))

(J; ``E`` Pa, ``nu``), the plane-stress St. Venant-Kirchhoff law. With the second Piola-Kirchhoff
stress ``S = lam tr(G) I + 2 mu G`` its gradient is ``dW/dx_a = A h F S beta_a`` and its Hessian::

    d2W/dx_a dx_b = A h [ (beta_a . S beta_b) I + lam (F beta_a)(F beta_b)^T
                          + 2 mu sum_ij g_a^ij (g_b^ij)^T ],   g_a^ij = (beta_a,i f_j + beta_a,j f_i) / 2

with ``f_i`` the columns of ``F``. Degrees of freedom of a triangle are ordered ``3 a + c``.
"""

import numpy as np

from ...physics.base.jit import kernel


def rest_frames(vertices, triangles):
    """``beta`` (T, 3, 2) (1/m) and rest areas (T,) (m^2) of the triangles of a rest mesh."""
    x0, x1, x2 = (vertices[triangles[:, m]] for m in range(3))
    d1, d2 = x1 - x0, x2 - x0
    normal = np.cross(d1, d2)
    area = 0.5 * np.linalg.norm(normal, axis=1)
    e1 = d1 / np.linalg.norm(d1, axis=1)[:, None]
    e2 = np.cross(normal / (2.0 * area)[:, None], e1)
    dm = np.empty((len(triangles), 2, 2))
    dm[:, 0, 0] = np.einsum("ij,ij->i", d1, e1)
    dm[:, 1, 0] = 0.0
    dm[:, 0, 1] = np.einsum("ij,ij->i", d2, e1)
    dm[:, 1, 1] = np.einsum("ij,ij->i", d2, e2)
    bm = np.linalg.inv(dm)  # rows: beta_1, beta_2
    beta = np.empty((len(triangles), 3, 2))
    beta[:, 1], beta[:, 2] = bm[:, 0], bm[:, 1]
    beta[:, 0] = -bm[:, 0] - bm[:, 1]
    return beta, area


def lame_plane_stress(youngs_modulus, poisson_ratio):
    """Plane-stress Lame constants ``(lam, mu)`` (Pa) of E (Pa) and nu."""
    nu = poisson_ratio
    return youngs_modulus * nu / (1.0 - nu * nu), youngs_modulus / (2.0 * (1.0 + nu))


@kernel(inline="always")
def _deformation(x, tri, beta, t, f):
    """Columns of ``F`` of triangle ``t`` into ``f`` (2, 3): ``f[i] = sum_a x_a beta_a,i``."""
    for i in range(2):
        for c in range(3):
            s = 0.0
            for a in range(3):
                s += x[tri[t, a], c] * beta[t, a, i]
            f[i, c] = s


@kernel(inline="always")
def _strain_stress(f, lam, mu):
    """Green strain (g11, g12, g22) and stress (s11, s12, s22) from the columns ``f`` of F."""
    g11 = 0.5 * (f[0, 0] ** 2 + f[0, 1] ** 2 + f[0, 2] ** 2 - 1.0)
    g22 = 0.5 * (f[1, 0] ** 2 + f[1, 1] ** 2 + f[1, 2] ** 2 - 1.0)
    g12 = 0.5 * (f[0, 0] * f[1, 0] + f[0, 1] * f[1, 1] + f[0, 2] * f[1, 2])
    tr = g11 + g22
    return g11, g12, g22, lam * tr + 2.0 * mu * g11, 2.0 * mu * g12, lam * tr + 2.0 * mu * g22


@kernel
def membrane_energy(x, tri, beta, area, lam, mu, h, f):
    """Stretching energy (J) of all triangles; ``f`` (2, 3) scratch."""
    total = 0.0
    for t in range(tri.shape[0]):
        _deformation(x, tri, beta, t, f)
        g11, g12, g22, _, _, _ = _strain_stress(f, lam, mu)
        tr = g11 + g22
        total += area[t] * h * (0.5 * lam * tr * tr + mu * (g11 * g11 + 2.0 * g12 * g12 + g22 * g22))
    return total


@kernel
def membrane_gradient(x, tri, beta, area, lam, mu, h, f, grad):
    """Adds the stretching energy's gradient (N) to ``grad`` (V, 3); ``f`` (2, 3) scratch."""
    for t in range(tri.shape[0]):
        _deformation(x, tri, beta, t, f)
        _, _, _, s11, s12, s22 = _strain_stress(f, lam, mu)
        ah = area[t] * h
        for a in range(3):
            b1, b2 = beta[t, a, 0], beta[t, a, 1]
            w1, w2 = s11 * b1 + s12 * b2, s12 * b1 + s22 * b2  # S beta_a
            for c in range(3):
                grad[tri[t, a], c] += ah * (f[0, c] * w1 + f[1, c] * w2)


@kernel
def membrane_hessians(x, tri, beta, area, lam, mu, h, f, out):
    """Each triangle's Hessian (N/m) of its stretching energy into ``out`` (T, 9, 9) (overwritten).

    With ``P_ij = f_i f_j^T`` the module doc's block of vertices ``(a, b)`` is
    ``A h [c00 P00 + c11 P11 + c01 P01 + c10 P10 + (beta_a . S beta_b) I]``,
    ``c00 = (lam + 2 mu) a1 b1 + mu a2 b2``, ``c11 = (lam + 2 mu) a2 b2 + mu a1 b1``,
    ``c01 = lam a1 b2 + mu a2 b1``, ``c10 = lam a2 b1 + mu a1 b2`` (``a_i``, ``b_i`` the
    components of ``beta_a``, ``beta_b``); the block of ``(b, a)`` is its transpose."""
    stiff = lam + 2.0 * mu
    for t in range(tri.shape[0]):
        _deformation(x, tri, beta, t, f)
        _, _, _, s11, s12, s22 = _strain_stress(f, lam, mu)
        ah = area[t] * h
        for a in range(3):
            a1, a2 = beta[t, a, 0], beta[t, a, 1]
            for b in range(a, 3):
                b1, b2 = beta[t, b, 0], beta[t, b, 1]
                geometric = a1 * (s11 * b1 + s12 * b2) + a2 * (s12 * b1 + s22 * b2)
                c00 = stiff * a1 * b1 + mu * a2 * b2
                c11 = stiff * a2 * b2 + mu * a1 * b1
                c01 = lam * a1 * b2 + mu * a2 * b1
                c10 = lam * a2 * b1 + mu * a1 * b2
                for c in range(3):
                    f0c, f1c = f[0, c], f[1, c]
                    for d in range(3):
                        f0d, f1d = f[0, d], f[1, d]
                        v = c00 * f0c * f0d + c11 * f1c * f1d + c01 * f0c * f1d + c10 * f1c * f0d
                        if c == d:
                            v += geometric
                        out[t, 3 * a + c, 3 * b + d] = ah * v
                        out[t, 3 * b + d, 3 * a + c] = ah * v
