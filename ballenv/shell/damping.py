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

import numpy as np
from numpy.typing import NDArray


def rigid_basis(x: NDArray[np.float64], mass: NDArray[np.float64]) -> NDArray[np.float64]:
    """``W = M Q`` (6, V, 3) (kg^(1/2)) for positions ``x`` (V, 3) and lumped masses ``mass`` (V,)."""
    centre = mass @ x / mass.sum()
    r = x - centre
    modes = np.zeros((6, len(x), 3))
    for k in range(3):
        modes[k, :, k] = 1.0
        axis = np.zeros(3)
        axis[k] = 1.0
        modes[3 + k] = np.cross(axis, r)
    flat = modes.reshape(6, -1)
    m = np.repeat(mass, 3)
    gram = (flat * m) @ flat.T
    q = np.linalg.solve(np.linalg.cholesky(gram), flat)  # rows M-orthonormal
    return (q * m).reshape(6, len(x), 3)


def deformation_rate(
    v: NDArray[np.float64], mass: NDArray[np.float64], basis: NDArray[np.float64]
) -> NDArray[np.float64]:
    """``(M - W W^T) v`` (V, 3) (kg m/s): the momentum of the velocity's non-rigid part."""
    coefficients = basis.reshape(6, -1) @ v.reshape(-1)
    return mass[:, None] * v - np.tensordot(coefficients, basis, axes=1)
