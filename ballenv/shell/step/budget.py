"""A shell's energy budget: what it may hold after a step, and the removal of a small excess.

The gas, gravity and the barriers are potentials; damping and friction only remove energy; only a
moving ground or a turning drum adds it, by the work it does (:func:`boundary_work`). So a shell's
energy (kinetic + stretching + bending + gas + gravity + barriers, J: ``implicit.total_energy``) may
never rise above its value at the start plus the work the grounds have done on it since, its budget
(with fixed grounds: its start energy); shells that have stepped jointly (they may have touched and
exchanged energy) share theirs: their energies and the barrier between them may not rise above the
sum of their budgets. Generalized-alpha is not energy-stable for a
nonlinear shell: a fast-spinning ball gains energy of order ``h^2`` over its first revolutions
(the discrete rotation stretches it) before the gain levels off. An accepted step whose
energy lies above the budget by ``excess`` (J) is corrected as the ring's
(``ballenv.physics.step.energy_budget``), keeping the momentum:

* if the kinetic energy of the shells' deformation ``K_d = sum 1/2 v^T (M - W W^T) v``
  (``W`` damping.py's rigid modes of each at the step's end) exceeds it, the velocities relative to
  their rigid motions are scaled by ``s = sqrt(1 - excess / K_d)`` (each shell's linear and angular
  momentum kept);
* else, if the kinetic energy relative to their centres of mass ``K_c`` exceeds it, the velocities
  relative to the centres' are scaled by ``sqrt(1 - excess / K_c)`` (spins lowered by that factor);
* else an excess within round-off (``ROUND_OFF`` of the energy's scale ``p_abs V0 + K``) is kept.

A larger gain than ``ENERGY_GROWTH_TOL`` of ``K_c`` (or one that cannot be paid) is a spurious
solution of a far too long implicit step: the step is rejected and retried shorter.
"""

import numpy as np
from numpy.typing import NDArray

from ..skin import damping
from ..touch import drum_friction, friction, ground
from .implicit import total_energy
from .stepdata import ShellStep

F64 = NDArray[np.float64]
ENERGY_GROWTH_TOL = 1e-2  # the largest gain of a step, relative to the kinetic energy about the centres
ROUND_OFF = 1e-12  # relative to p_abs V0 + K


class Sharing:
    """Which shells share a budget: disjoint sets of shell indices, joined for good."""

    def __init__(self, n_shells: int) -> None:
        self.label = list(range(n_shells))

    def join(self, group: list[int]) -> None:
        """Puts the shells of ``group`` (and those sharing with them) in one set."""
        old = {self.label[k] for k in group}
        new = min(old)
        self.label = [new if label in old else label for label in self.label]

    def sets(self) -> list[list[int]]:
        """The sets, each sorted, ordered by their first shell."""
        out: dict[int, list[int]] = {}
        for k, label in enumerate(self.label):
            out.setdefault(label, []).append(k)
        return list(out.values())


def energies(steps: list[ShellStep], x: F64, v: F64) -> list[float]:
    """Each shell's energy (J) at positions ``x`` and velocities ``v`` (shells, V, 3)."""
    return [total_energy(st, x[k], v[k]) for k, st in enumerate(steps)]


def boundary_work(st: ShellStep, heights0: F64, x1: F64, h: float) -> float:
    """The work (J) the moving grounds did on a shell in the step of ``h`` (s) just taken from
    ``st.start.x0`` (m) to ``x1`` (m), its planes moved from the offsets ``heights0`` (m, at the
    step's start) to ``st.heights`` (at its end) and their surfaces slid by ``st.slide``::

        W = B(x0; d(t1)) - B(x0; d(t0)) + sum_ig F_ig . s_g

    The step takes the barriers against the planes at its end (touch/motion.py), as though each
    plane moved first, with the shell held at ``x0``, and the shell then stepped against fixed
    planes: the first term (the barriers' energy ``B``, ground.py) is what that move did; the
    second, the work of friction's force ``F = -grad D`` (N, at ``x1``, friction.py) through the
    surfaces' slides ``s_g`` (m), and likewise through the turning drums' (drum_friction.py; a drum's
    geometry does not move, so it has no first term). A moving ground's power on a vertex,
    ``f . v = f . w + f . (v - w)``, is its work; the rest (friction on the slip) only dissipates. The
    first term bounds what a dissipative step can gain from the move, so a legitimate gain is never
    clipped; it exceeds the work ``lambda n . (d(t1) - d(t0))`` by about ``k (n . (d(t1) - d(t0)))^2
    / 2`` (``k`` the barrier's stiffness, N/m), which the step dissipates: a ball carried up by a
    plate is credited a few times the work of lifting it. 0 on fixed grounds."""
    sp, n = st.start, st.normals
    lift = ground.barrier_energy(sp.x0, n, st.heights, st.dhat, st.kappa)
    lift -= ground.barrier_energy(sp.x0, n, heights0, st.dhat, st.kappa)
    e = st.slip_speed * h
    drag = friction.friction_work(np.ascontiguousarray(x1), sp.x0, n, st.slide, sp.lam, st.mu, e, st.work.u3)
    if st.drums is not None:
        drag += drum_friction.friction_work(np.ascontiguousarray(x1), sp.x0, st.drums, e)
    return float(lift + drag)


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


def hold(steps: list[ShellStep], xs: list[F64], vs: list[F64], energy: float, budget: float) -> bool:
    """Holds the states ``(xs[k], vs[k])`` (V, 3) of shells that share a budget (``steps``) of
    energy ``energy`` (J) to ``budget`` (J), scaling each ``vs[k]`` in place by the same factor as
    the module doc says; False if the step must be rejected."""
    excess = energy - budget
    if excess <= 0.0:
        return True
    deform = [_deformation_velocity(st, x, v) for st, x, v in zip(steps, xs, vs, strict=True)]
    centred = [_about_centre(st, v) for st, v in zip(steps, vs, strict=True)]
    k_d = sum(_kinetic(st, u) for st, u in zip(steps, deform, strict=True))
    k_c = sum(_kinetic(st, u) for st, u in zip(steps, centred, strict=True))
    scale = sum(st.problem.model.absolute_pressure[0] * st.problem.model.rest_volume for st in steps)
    if excess <= ROUND_OFF * (scale + k_c):
        return True
    if excess > ENERGY_GROWTH_TOL * k_c:
        return False
    pool, parts = (k_d, deform) if k_d > excess else (k_c, centred)
    keep = np.sqrt(1.0 - excess / pool)
    for v, u in zip(vs, parts, strict=True):
        v -= (1.0 - keep) * u
    return True
