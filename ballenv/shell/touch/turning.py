"""Prescribed turning of the drums (``Scene.drums``): the angle each turns over a step, which
friction's slip is taken against (drum_friction.py) and the energy budget credits the work through.

A drum turns about its axis at ``Omega(t) = Omega_0 min(1, t / T)`` (rad/s; ``T`` its spin-up, s,
0: none), so it has turned, since t = 0, by the angle (rad)::

    phi(t) = Omega_0 t^2 / (2 T)   (t < T),        Omega_0 (t - T / 2)   (t >= T)

and over a step ``[t, t + h]`` by ``theta = phi(t + h) - phi(t)``. The geometry does not change, so
the step needs no limit; fixed drums are never read here.
"""

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from ..scene import Drum

F64 = NDArray[np.float64]


class Turning:
    """The turning of a scene's drums, and the step's record it writes: ``turn`` (D,) rad, the angle
    each drum turns over the step being tried (read by the compiled step: ``Drums.turn``)."""

    def __init__(self, drums: Sequence["Drum"], turn: F64) -> None:
        self.omega = np.array([d.angular_velocity for d in drums], dtype=np.float64)
        self.spin_up = np.array([d.spin_up for d in drums], dtype=np.float64)
        self.turn = turn

    def angular_velocities(self, t: float) -> F64:
        """``Omega(t)`` (D,) rad/s (module doc)."""
        ramp = np.minimum(1.0, t / np.maximum(self.spin_up, 1e-300))
        return self.omega * np.where(self.spin_up > 0.0, ramp, 1.0)

    def angles(self, t: float) -> F64:
        """``phi(t)`` (D,) rad, the angle each drum has turned since t = 0 (module doc)."""
        T = self.spin_up
        ramping = t < T
        return self.omega * np.where(ramping, t * t / (2.0 * np.where(ramping, T, 1.0)), t - 0.5 * T)

    def prepare(self, t: float, h: float) -> None:
        """Writes ``turn``, the angles the drums turn over the step ``[t, t + h]`` (s)."""
        self.turn[:] = self.angles(t + h) - self.angles(t)
