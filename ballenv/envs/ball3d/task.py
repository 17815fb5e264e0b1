"""The task of InflatedBall3D-v0: its actions on the simulator, its bookkeeping of flights and
apexes, its reward and its episode ends (SI units).

* **Pressure mode**: the command ``p = p_lo + (a + 1)/2 (p_hi - p_lo)`` (Pa); the gas setpoint moves
  toward it at most ``pressure_rate dt``, and the gas amount ramps to it over the control step
  (``Simulation.ramp_rest_pressure``).
* **Paddle mode**: ``a = (a_J, a_x, a_y)``: the impulse ``J = (a_J + 1)/2 J_max`` (N s) along the
  direction ``d = (sin th cos ph, sin th sin ph, -cos th)``, tilted from straight down by
  ``th = theta_max min(1, |(a_x, a_y)|)`` toward the azimuth ``ph = atan2(a_y, a_x)``. The paddle is a
  plane across ``d`` coming from above: it meets the vertices within ``paddle_depth`` of the ball's
  extreme point against ``d`` (smallest ``d . x_i``) and pushes each with ``J d / (n T)`` over the
  strike's duration ``T``, so the momentum changes by ``J d`` and the angular momentum about the
  centre by the forces' moment ``sum_i (x_i - c) x J d / n``: a tilted strike steers the ball, and
  one that meets an off-centre patch spins it.
* **Apex measure**: while the ball rises in flight, the centre's ballistic apex ``z + v_z^2 / (2 g)``;
  otherwise the last flight apex, capped by ``r_rest + rise``, where ``rise`` (m) is the height the
  ball's free energy could still lift it: kinetic energy plus the skin's and gas's energy above the
  free ball at rest at the same gas amount, over ``m g``, plus the centre's height above ``r_rest``.
* **Reward**: DeepMind Control's gaussian tolerance of the relative apex error (``reward_margin``),
  times, in paddle mode, that of the centre's horizontal distance to the target spot
  (``spot_margin``, m); in [0, 1], 0 once the simulator failed.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ...shell import Shell, equilibrium
from ...shell.skin import potential
from ...shell.skin.model import build_model, build_workspace
from ...shell.steering import Simulation
from ..task import height_reward

if TYPE_CHECKING:
    from .config import Ball3DConfig

F64 = NDArray[np.float64]
REST_GRID = 9  # rest pressures at which the free ball's rest energy is tabulated


def strike_direction(config: Ball3DConfig, ax: float, ay: float) -> F64:
    """The strike's unit direction (3,) from the tilt actions ``ax``, ``ay`` in [-1, 1] (module doc)."""
    theta = config.paddle_max_tilt * min(1.0, math.hypot(ax, ay))
    phi = math.atan2(ay, ax)
    return np.array([math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), -math.cos(theta)])


def met_vertices(x: F64, direction: F64, depth: float) -> NDArray[np.int64]:
    """The vertices a plane across ``direction`` moving along it meets first: within ``depth`` (m)
    of the smallest ``direction . x_i``."""
    reach = x @ direction
    return np.flatnonzero(reach <= reach.min() + depth)


def strike_forces(x: F64, direction: F64, impulse: float, depth: float, duration: float) -> F64:
    """The forces (V, 3) N that deliver ``impulse`` (N s) along ``direction`` over ``duration`` (s),
    shared equally by the :func:`met_vertices` within ``depth`` (m)."""
    met = met_vertices(x, direction, depth)
    forces = np.zeros_like(x)
    forces[met] = direction * (impulse / (len(met) * duration))
    return forces


class RestEnergy:
    """The free ball at rest (no gravity, no ground) as a function of its gas amount: the skin's and
    gas's energy (J) and the radius (m), tabulated at ``REST_GRID`` rest pressures over ``low``,
    ``high`` (Pa) and interpolated linearly."""

    def __init__(
        self, shell: Shell, gas_exponent: float, atmospheric_pressure: float, low: float, high: float
    ):
        self.pressures = np.linspace(low, high, REST_GRID) if high > low else np.array([low])
        energies, radii = [], []
        for p in self.pressures:
            sh = replace(shell, pressure=float(p), position=(0.0, 0.0, 0.0))
            x = equilibrium(sh, gas_exponent=gas_exponent, atmospheric_pressure=atmospheric_pressure).x
            model = build_model(sh, gas_exponent, atmospheric_pressure)
            energies.append(float(potential.energy(model, build_workspace(model), x, np.zeros_like(x))))
            radii.append(float(np.linalg.norm(x - x.mean(axis=0), axis=1).mean()))
        self.energies, self.radii = np.array(energies), np.array(radii)

    def at(self, p0: float) -> tuple[float, float]:
        """(energy J, radius m) of the free ball at rest pressure ``p0`` (Pa)."""
        if len(self.pressures) == 1:
            return float(self.energies[0]), float(self.radii[0])
        return (
            float(np.interp(p0, self.pressures, self.energies)),
            float(np.interp(p0, self.pressures, self.radii)),
        )


def rise(sim: Simulation, rest: RestEnergy, gravity: float) -> tuple[float, float]:
    """(rise m, r_rest m) of the ball now (module doc)."""
    st = sim.run.steps[0]
    model = st.problem.model
    x, v = np.ascontiguousarray(sim.x[0]), sim.v[0]
    kinetic = 0.5 * float(model.mass @ np.sum(v * v, axis=1))
    skin = float(potential.energy(model, st.problem.ws, x, np.zeros_like(x)))
    energy, radius = rest.at(sim.rest_pressure(0))
    weight = float(model.mass.sum()) * gravity
    height = float(model.mass @ x[:, 2]) / float(model.mass.sum())
    return (kinetic + skin - energy) / weight + height - radius, radius


def predicted_apex(
    airborne: bool, z: float, vz: float, gravity: float, last_apex: float, cap: float
) -> float:
    """Height (m) of the apex the reward measures (module doc); ``cap = r_rest + rise``."""
    if airborne and vz > 0.0:
        return z + 0.5 * vz * vz / gravity
    return min(last_apex, cap)


def reward(config: Ball3DConfig, apex: float, target: float, distance: float) -> tuple[float, float, float]:
    """(reward, height term, spot term) of the apex measure ``apex`` (m) against ``target`` (m) and
    the centre's horizontal ``distance`` (m) to the spot (module doc)."""
    height = float(height_reward(abs(apex - target) / target, config.reward_margin))
    spot = float(height_reward(distance, config.spot_margin)) if config.paddle else 1.0
    return height * spot, height, spot
