"""Damping of a shell's deformation only: ``F_i = -c m_i (v_i - v_rigid,i)`` (N; ``c`` in 1/s).

``v_rigid`` is the mass-weighted least-squares rigid motion of the velocity field (a translation
plus a spin about the centre of mass), the M-orthogonal projection of ``v`` on the six rigid modes
``r_k`` of the positions ``x`` (m). With ``W = M Q`` (6 columns; ``Q`` the rigid modes made
M-orthonormal, ``Q^T M Q = I``)::

    F = -c (M - W W^T) v,   the Rayleigh dissipation function R(v) = c / 2 v^T (M - W W^T) v  (W)

so a translation, a spin or rolling (``v = r Q a``) feels no force, and the deformation rate loses
energy at ``2 R``. The step takes ``W`` at its start (``x0``): the damping matrix is the diagonal
``c M`` less a rank-6 term.
"""

import math

from ...physics.base.jit import kernel


@kernel
def rigid_basis(x, mass, out):
    """``W = M Q`` (6, V, 3) (kg^(1/2)) into ``out`` for positions ``x`` (V, 3) m and lumped masses
    ``mass`` (V,) kg: the rigid modes (three translations, three spins about the centre of mass)
    made M-orthonormal by Gram-Schmidt in the M inner product, in that order."""
    total = 0.0
    cx = cy = cz = 0.0
    for i in range(x.shape[0]):
        total += mass[i]
        cx += mass[i] * x[i, 0]
        cy += mass[i] * x[i, 1]
        cz += mass[i] * x[i, 2]
    centre = (cx / total, cy / total, cz / total)
    for k in range(6):
        for i in range(x.shape[0]):
            for c in range(3):
                out[k, i, c] = _mode(k, c, x[i, 0] - centre[0], x[i, 1] - centre[1], x[i, 2] - centre[2])
        for j in range(k):  # q_k -= (q_j^T M q_k) q_j, with out[j] = M q_j
            f = 0.0
            for i in range(x.shape[0]):
                for c in range(3):
                    f += out[j, i, c] * out[k, i, c]
            for i in range(x.shape[0]):
                for c in range(3):
                    out[k, i, c] -= f * out[j, i, c] / mass[i]
        norm = 0.0
        for i in range(x.shape[0]):
            for c in range(3):
                norm += mass[i] * out[k, i, c] * out[k, i, c]
        scale = 1.0 / math.sqrt(norm)
        for i in range(x.shape[0]):
            for c in range(3):
                out[k, i, c] *= scale * mass[i]


@kernel(inline="always")
def _mode(k, c, rx, ry, rz):
    """Component ``c`` of rigid mode ``k`` at the offset ``r`` from the centre: ``e_k`` (k < 3) or
    ``e_(k-3) x r``."""
    if k < 3:
        return 1.0 if c == k else 0.0
    a = k - 3
    if a == 0:
        return (0.0, -rz, ry)[c]
    if a == 1:
        return (rz, 0.0, -rx)[c]
    return (-ry, rx, 0.0)[c]


@kernel
def deformation_rate(v, mass, basis, out):
    """``(M - W W^T) v`` (V, 3) (kg m/s) into ``out``: the momentum of the velocity's non-rigid part."""
    for i in range(v.shape[0]):
        for c in range(3):
            out[i, c] = mass[i] * v[i, c]
    for k in range(basis.shape[0]):
        f = 0.0
        for i in range(v.shape[0]):
            for c in range(3):
                f += basis[k, i, c] * v[i, c]
        for i in range(v.shape[0]):
            for c in range(3):
                out[i, c] -= f * basis[k, i, c]
