"""A shell's energy budget: what it may hold after a step, and the removal of a small excess.

Nothing in a shell scene adds energy: the gas, gravity and the barriers are potentials; damping
and friction only remove it (the grounds are fixed). So a shell's energy (kinetic + stretching +
bending + gas + gravity + barriers, J: ``implicit.total_energy``) may never rise above its value
at the start, its budget. Generalized-alpha is not energy-stable for a
nonlinear shell: a fast-spinning ball gains energy of order ``h^2`` over its first revolutions
(the discrete rotation stretches it) before the gain levels off. An accepted step whose
energy lies above the budget by ``excess`` (J) is corrected as the ring's
(``ballenv.physics.step.energy_budget``), keeping the momentum:

* if the kinetic energy of the shell's deformation ``K_d = 1/2 v^T (M - W W^T) v``
  (``W`` damping.py's rigid modes at the step's end) exceeds it, the velocity relative to the
  rigid motion is scaled by ``s = sqrt(1 - excess / K_d)`` (linear and angular momentum kept);
* else, if the kinetic energy relative to the centre of mass ``K_c`` exceeds it, the velocities
  relative to the centre's are scaled by ``sqrt(1 - excess / K_c)`` (spin lowered by that factor);
* else an excess within round-off (``ROUND_OFF`` of the energy's scale ``p_abs V0 + K``) is kept.

A larger gain than ``ENERGY_GROWTH_TOL`` of ``K_c`` (or one that cannot be paid) is a spurious
solution of a far too long implicit step: the step is rejected and retried shorter.
"""

import numpy as np
from numpy.typing import NDArray

from . import damping
from .implicit import total_energy
from .stepdata import ShellStep

F64 = NDArray[np.float64]
ENERGY_GROWTH_TOL = 1e-2  # the largest gain of a step, relative to the kinetic energy about the centre
ROUND_OFF = 1e-12  # relative to p_abs V0 + K


def energies(steps: list[ShellStep], x: F64, v: F64) -> list[float]:
    """Each shell's energy (J) at positions ``x`` and velocities ``v`` (shells, V, 3)."""
    return [total_energy(st, x[k], v[k]) for k, st in enumerate(steps)]


def _deformation_velocity(st: ShellStep, x: F64, v: F64) -> F64:
    """``v - v_rigid`` (V, 3) m/s: the velocity less its mass-weighted least-squares rigid motion."""
    mass = st.problem.model.mass
    basis, rate = np.zeros((6, len(x), 3)), np.zeros_like(x)
    damping.rigid_basis(x, mass, basis)
    damping.deformation_rate(v, mass, basis, rate)
    return rate / mass[:, None]


def _about_centre(st: ShellStep, v: F64) -> F64:
    """``v - V`` (V, 3) m/s, ``V`` the centre of mass's velocity."""
    mass = st.problem.model.mass
    return v - mass @ v / mass.sum()


def _kinetic(st: ShellStep, u: F64) -> float:
    return 0.5 * float(np.sum(st.problem.model.mass[:, None] * u * u))


def hold(st: ShellStep, x: F64, v: F64, energy: float, budget: float) -> bool:
    """Holds a shell's state ``(x, v)`` (V, 3) of energy ``energy`` (J) to its ``budget`` (J),
    scaling ``v`` in place as the module doc says; False if the step must be rejected."""
    excess = energy - budget
    if excess <= 0.0:
        return True
    deform, centred = _deformation_velocity(st, x, v), _about_centre(st, v)
    k_d, k_c = _kinetic(st, deform), _kinetic(st, centred)
    model = st.problem.model
    if excess <= ROUND_OFF * (model.absolute_pressure * model.rest_volume + k_c):
        return True
    if excess > ENERGY_GROWTH_TOL * k_c:
        return False
    pool, part = (k_d, deform) if k_d > excess else (k_c, centred)
    v -= (1.0 - np.sqrt(1.0 - excess / pool)) * part
    return True
