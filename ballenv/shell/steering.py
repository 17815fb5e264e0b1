"""``Simulation``: a run of shells advanced piece by piece, with each shell's gas amount and the
forces on its vertices set between pieces: what an environment or a controller drives (SI units).

The pieces step as ``simulate`` does (simulation.py); a piece ends on the time asked for.

* **Gas amount.** It is set as the rest pressure ``p0`` (Pa, gauge at the rest volume ``V0``): the
  gas law's constant is ``(p0 + p_atm) V0^gamma``. The gas at the current volume follows at once,
  ``p = (p0 + p_atm) (V0 / V)^gamma - p_atm``.
* **Gas ramps.** ``ramp_rest_pressure(shell, p1, t1)`` moves the rest pressure linearly in time from
  its value now to ``p1`` at ``t1`` (s); each step tried holds the value of its end time, as a
  pump's flow would, and from ``t1`` on the gas holds ``p1``.
* **External forces.** Forces ``f_i`` (N, on each vertex, besides gravity) stay until set again.
  They enter the step as the loads of the potential, ``-f . x``, so a force held over the steps
  ``[t0, t1]`` changes the momentum by exactly ``(sum_i f_i) (t1 - t0)``; internal forces, damping and
  a ground or drum that is not touched add none.
* **Carried acceleration.** A change of the forces moves the integrator's carried acceleration
  (generalized-alpha's ``a``) with it, ``da_i = (f_new - f_old)_i / m_i``: a step then starts
  consistent with the forces it steps under, so the momentum of a held force is exact (a carried
  acceleration of the old forces would spread part of the change into the steps after it). A
  change of the gas amount leaves it: a ramp changes the gas a little at every step, and moving
  the carried acceleration with each change (by ``(p_new - p_old) (dV/dx_i) / m_i``) makes
  generalized-alpha overshoot as from ``a = F / m``, ringing the ball (more, shorter steps).
* **Energy budget.** Both settings change the shell's energy at a fixed state by
  ``dE = E(x, v; new) - E(x, v; old)`` (J: ``-(f_new - f_old) . x`` for the forces, ``U_new(V) -
  U_old(V)`` for the gas), and the budget (step/budget.py) is credited with it. Over
  a force held from positions ``x0`` to ``x1``, the credits at its start and end sum to
  ``f . (x1 - x0)``: the work it did. For the gas, ``dE`` is the pump's work at the current shape.
"""

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .scene import Scene
from .simulation import Run, Trajectory
from .skin.gas import gas_energy, gauge_pressure, volume
from .step import budget

F64 = NDArray[np.float64]
MAX_REST_PRESSURE = 1e8  # Pa, the largest rest pressure a shell may be set to


class Simulation:
    """Shells of ``scene`` from t = 0 (positions ``x0``, velocities ``v0`` as in ``simulate``),
    recorded every accepted step or every ``output_dt`` (s), or not at all if not ``record`` (then
    :meth:`trajectory` holds no records, and its events and stats only); see the module doc."""

    def __init__(
        self,
        scene: Scene,
        x0: ArrayLike | None = None,
        v0: ArrayLike | None = None,
        output_dt: float | None = None,
        record: bool = True,
    ) -> None:
        self.run = Run(scene, x0, v0, output_dt, record)
        self.gravity_loads = [st.problem.loads.copy() for st in self.run.steps]  # (V, 3) N each
        self._ramps: dict[int, tuple[float, float, float, float]] = {}  # shell: p0 Pa, t0 s, p1 Pa, t1 s

    @property
    def t(self) -> float:
        """Time reached (s)."""
        return self.run.t

    @property
    def x(self) -> F64:
        """Positions (shells, V, 3) m (the run's array: copy it to keep it)."""
        return self.run.x

    @property
    def v(self) -> F64:
        """Velocities (shells, V, 3) m/s (the run's array: copy it to keep it)."""
        return self.run.v

    @property
    def contact_force(self) -> F64:
        """The grounds', drums' and contact barriers' force on each vertex (shells, V, 3) N."""
        return self.run.force

    def advance(self, t_end: float) -> None:
        """Steps to ``t_end`` (s), landing on it; ``SimulationError`` if a step is halved below
        ``Scene.dt_min``."""
        if not (isinstance(t_end, (int, float)) and math.isfinite(t_end) and t_end >= self.t):
            raise ValueError(
                f"Simulation.advance.t_end = {t_end!r} is out of range: must be a finite time "
                f">= t = {self.t!r} s"
            )
        self.run.advance(float(t_end))

    def gauge_pressure(self, shell: int) -> float:
        """Gauge pressure of the gas of ``shell`` now (Pa)."""
        st = self.run.steps[self._shell(shell)]
        return float(gauge_pressure(st.problem.model, volume(self.x[shell], st.problem.model.triangles)))

    def rest_pressure(self, shell: int) -> float:
        """The gas amount of ``shell`` as the gauge pressure at its rest volume (Pa)."""
        model = self.run.steps[self._shell(shell)].problem.model
        return float(model.absolute_pressure[0]) - model.atmospheric_pressure

    def set_rest_pressure(self, shell: int, p0: float) -> None:
        """Sets the gas amount of ``shell`` to the rest pressure ``p0`` (Pa gauge; module doc)."""
        k = self._shell(shell)
        self._check_rest_pressure(k, p0, "set_rest_pressure.p0")
        self._ramps.pop(k, None)
        self._set_amount(k, float(p0))

    def _check_rest_pressure(self, k: int, p0: object, name: str) -> None:
        low = -self.run.steps[k].problem.model.atmospheric_pressure
        if not (isinstance(p0, (int, float)) and low < p0 <= MAX_REST_PRESSURE):
            raise ValueError(
                f"Simulation.{name} = {p0!r} is out of range: must be in ({low:g}, "
                f"{MAX_REST_PRESSURE:g}] Pa (gauge)"
            )

    def _set_amount(self, k: int, p0: float) -> None:
        """Sets shell ``k``'s gas amount to the rest pressure ``p0`` (Pa gauge), crediting its budget."""
        st = self.run.steps[k]
        model = st.problem.model
        if model.absolute_pressure[0] == p0 + model.atmospheric_pressure:
            return
        # only the gas's term changes: dE = U_new(V) - U_old(V)
        vol = volume(np.ascontiguousarray(self.x[k]), model.triangles)
        before = gas_energy(model, vol)
        model.absolute_pressure[0] = p0 + model.atmospheric_pressure
        self.run.budget[k] += float(gas_energy(model, vol) - before)

    def ramp_rest_pressure(self, shell: int, p1: float, t1: float) -> None:
        """Ramps the gas amount of ``shell`` to the rest pressure ``p1`` (Pa gauge) at ``t1`` (s)
        (module doc); a ramp already under way for the shell is replaced."""
        k = self._shell(shell)
        if not (isinstance(t1, (int, float)) and math.isfinite(t1) and t1 > self.t):
            raise ValueError(
                f"Simulation.ramp_rest_pressure.t1 = {t1!r} is out of range: must be a finite time "
                f"> t = {self.t!r} s"
            )
        p0, t0 = self.rest_pressure(k), self.t
        self._check_rest_pressure(k, p1, "ramp_rest_pressure.p1")
        self._ramps[k] = (p0, t0, float(p1), float(t1))
        if self._hold_ramps not in self.run.preparations:
            self.run.preparations.append(self._hold_ramps)

    def _hold_ramps(self, t: float, h: float) -> None:
        """Sets each ramping shell's gas amount to its ramp's value at ``t + h`` (s)."""
        for k, (p0, t0, p1, t1) in list(self._ramps.items()):
            s = min(1.0, (t + h - t0) / (t1 - t0))
            self._set_amount(k, p0 + s * (p1 - p0))
            if t + h >= t1:
                del self._ramps[k]

    def forces(self, shell: int) -> F64:
        """The external forces on the vertices of ``shell`` (V, 3) N (a copy)."""
        k = self._shell(shell)
        return self.run.steps[k].problem.loads - self.gravity_loads[k]

    def set_forces(self, shell: int, forces: ArrayLike) -> None:
        """Sets the external forces on the vertices of ``shell`` (V, 3) N (module doc)."""
        k = self._shell(shell)
        loads = self.run.steps[k].problem.loads
        f = np.asarray(forces, dtype=np.float64)
        if f.shape != loads.shape or not np.all(np.isfinite(f)):
            raise ValueError(
                f"Simulation.set_forces.forces must be a finite array of shape {loads.shape} (N), "
                f"got shape {f.shape}"
            )
        change = f - (loads - self.gravity_loads[k])  # only the loads' term -f . x changes
        self.run.budget[k] -= float(np.sum(change * self.x[k]))
        self.run.a[k] += change / self.run.steps[k].problem.model.mass[:, None]
        np.add(self.gravity_loads[k], f, out=loads)

    def energy(self, shell: int) -> float:
        """Energy of ``shell`` now (J): kinetic, skin, gas, gravity, external forces' and barriers'."""
        k = self._shell(shell)
        return budget.energies([self.run.steps[k]], self.x[k : k + 1], self.v[k : k + 1])[0]

    def trajectory(self) -> Trajectory:
        """What has been recorded so far."""
        return self.run.trajectory()

    def _shell(self, shell: int) -> int:
        n = len(self.run.steps)
        if not (isinstance(shell, (int, np.integer)) and 0 <= shell < n):
            raise ValueError(
                f"Simulation.shell = {shell!r} is out of range: must be an index in [0, {n - 1}]"
            )
        return int(shell)
