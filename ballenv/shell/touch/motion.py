"""Prescribed rigid motion of the grounds (``Scene.grounds``): where each plane is at a time, how
fast its surface moves, and how long a step may be so that a plane moving toward a shell never
jumps through it.

A ground ``g`` is the half-space ``n . x >= d(t)`` with a fixed unit normal ``n`` and the offset (m)

    d(t) = d0 + (n . u) t + A sin(omega t),          omega = 2 pi f,

the ring's convention (``ballenv.physics.ground.motion``): a constant velocity ``u`` (m/s; along
the plane a conveyor belt, along ``n`` a rising or sinking plate) plus an oscillation along ``n``
of amplitude ``A`` (m) and frequency ``f`` (Hz). Its surface moves with the velocity (m/s)

    w(t) = u + A omega cos(omega t) n,

whose part along the plane, ``T u`` (``T = I - n n^T``), is constant: over a step of ``h`` (s) the
surface slides by ``s = h T u`` (m), which friction's slip is taken against (friction.py).

A step ``[t0, t1]`` takes every barrier against the planes at ``d(t1)`` (the step's end, as the
barrier is implicit), starting from a state that is feasible for ``d(t0)``. A plane approaches at
most at the rate ``d'(t) <= r = max(0, n . u + A omega)`` (m/s), so a step of
``h <= STEP_FRACTION dist / r`` (``dist`` the smallest distance, m, of a shell's vertex from the
plane at ``t0``) moves it less than ``STEP_FRACTION`` of the way to the nearest vertex: the start
stays strictly above it and no vertex can be passed. Within reach of an oscillating plane
(``dist < dhat + 2 A``) a step is also at most ``1 / (PERIOD_STEPS f)``, so that the steps follow
the oscillation. Fixed grounds are never read here: a scene of fixed grounds steps as before.
"""

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from ..scene import Ground

F64 = NDArray[np.float64]
STEP_FRACTION = 0.5  # of the distance to the nearest vertex a plane may advance in one step
PERIOD_STEPS = 20  # steps per period of an oscillating plane within reach, at least


class Motion:
    """The motion of a scene's grounds, and the step's records it writes: ``heights`` (G,) m, the
    planes' offsets at the end of the step being tried, and ``slide`` (G, 3) m, their surfaces'
    slide ``h T u`` over it (both read by the compiled step: ``ShellStep.heights``,
    ``ShellStep.slide``)."""

    def __init__(self, grounds: Sequence["Ground"], heights: F64, slide: F64, dhat: float) -> None:
        self.normals = np.array([g.normal for g in grounds], dtype=np.float64).reshape(-1, 3)
        self.d0 = np.array([g.height for g in grounds], dtype=np.float64)
        self.velocity = np.array([g.velocity for g in grounds], dtype=np.float64).reshape(-1, 3)
        self.amplitude = np.array([g.amplitude for g in grounds], dtype=np.float64)
        self.omega = 2.0 * math.pi * np.array([g.frequency for g in grounds], dtype=np.float64)
        self.normal_speed = np.einsum("ga,ga->g", self.normals, self.velocity)
        self.belt = self.velocity - self.normal_speed[:, None] * self.normals  # T u, m/s
        self.rate = np.maximum(self.normal_speed + self.amplitude * self.omega, 0.0)
        self.heights, self.slide, self.dhat = heights, slide, dhat

    def offsets(self, t: float) -> F64:
        """``d(t)`` (G,) m of every plane (module doc)."""
        return self.d0 + self.normal_speed * t + self.amplitude * np.sin(self.omega * t)

    def surface_velocities(self, t: float) -> F64:
        """``w(t)`` (G, 3) m/s of every plane's surface (module doc)."""
        wn = self.amplitude * self.omega * np.cos(self.omega * t)
        return self.velocity + wn[:, None] * self.normals

    def distances(self, x: F64, t: float) -> F64:
        """(G,) m: the smallest distance of a vertex of ``x`` (..., 3) from each plane at ``t``."""
        return (x.reshape(-1, 3) @ self.normals.T).min(axis=0) - self.offsets(t)

    def step_limit(self, x: F64, t: float) -> float:
        """The longest step (s) from positions ``x`` (..., 3) at ``t`` (s) (module doc); inf if none."""
        gaps = self.distances(x, t)
        limit = math.inf
        for g, gap in enumerate(gaps):
            if self.rate[g] > 0.0:
                limit = min(limit, STEP_FRACTION * float(gap) / float(self.rate[g]))
            if self.amplitude[g] > 0.0 and gap < self.dhat + 2.0 * self.amplitude[g]:
                limit = min(limit, 2.0 * math.pi / (PERIOD_STEPS * float(self.omega[g])))
        return limit

    def prepare(self, x: F64, t: float, h: float) -> float:
        """The step to try from ``x`` at ``t`` (s): ``h`` (s) or the shorter :meth:`step_limit`;
        writes the planes' ``heights`` at its end and their ``slide`` over it."""
        h = min(h, self.step_limit(x, t))
        self.heights[:] = self.offsets(t + h)
        self.slide[:] = h * self.belt
        return h
