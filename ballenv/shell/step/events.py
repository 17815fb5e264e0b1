"""Events of a shell located inside an accepted step ``[t, t + h]`` (s): the apex (the centre of
mass's upward velocity crossing zero from above), touchdown and liftoff.

The centre of mass's height along ``up`` (the unit vector against gravity; +z without gravity) is
the cubic Hermite interpolant of its end heights ``z0``, ``z1`` (m) and velocities ``w0``, ``w1``
(m/s): ``z(s) = H(z0, z1, h w0, h w1; s)``, ``s = (tau - t) / h``. An apex is the root in ``[0, 1]`` of
``z'(s)``, a quadratic, where ``w0 > 0 >= w1``; its height is ``z`` there. The shell touches a
ground while a vertex is within the barrier's reach ``dhat`` (m) of it; touchdown and liftoff are
placed where the smallest distance crosses ``dhat``, linearly between the step's ends.
"""

import math

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


def hermite(y0: float, y1: float, d0: float, d1: float, s: float) -> float:
    """Cubic Hermite on [0, 1] with end values y0, y1 and end slopes d0, d1 (per unit s)."""
    s2, s3 = s * s, s * s * s
    return (2 * s3 - 3 * s2 + 1) * y0 + (s3 - 2 * s2 + s) * d0 + (-2 * s3 + 3 * s2) * y1 + (s3 - s2) * d1


def apex_fraction(z0: float, z1: float, d0: float, d1: float) -> float:
    """The ``s`` in [0, 1] where the Hermite interpolant's slope (``d0 > 0 >= d1``) is zero."""
    # H'(s) = 6 (z0 - z1) (s^2 - s) + d0 (3 s^2 - 4 s + 1) + d1 (3 s^2 - 2 s) = a s^2 + b s + c
    a = 6.0 * (z0 - z1) + 3.0 * d0 + 3.0 * d1
    b = -6.0 * (z0 - z1) - 4.0 * d0 - 2.0 * d1
    c = d0
    disc = math.sqrt(max(b * b - 4.0 * a * c, 0.0))
    q = -0.5 * (b + math.copysign(disc, b))  # the roots q / a and c / q without cancellation
    roots = [c / q] if q != 0.0 else []
    if a != 0.0:
        roots.append(q / a)
    inside = [r for r in roots if -1e-12 <= r <= 1.0 + 1e-12]
    return min(max(min(inside) if inside else 1.0, 0.0), 1.0)


def centre(mass: NDArray[np.float64], x: NDArray[np.float64]) -> NDArray[np.float64]:
    """The mass-weighted mean of ``x`` (V, 3)."""
    return mass @ x / mass.sum()


def end(up: F64, mass: F64, x: F64, v: F64, gap: float) -> tuple[float, float, float]:
    """A step end's ``(z m, w m/s, gap m)``: the centre of mass's height along ``up`` and its rate,
    and the smallest ground distance ``gap`` given, of positions ``x`` and velocities ``v`` (V, 3)."""
    return float(up @ centre(mass, x)), float(up @ centre(mass, v)), gap


def detect(
    t: float, h: float, shell: int, before: tuple[float, float, float], after: tuple[float, float, float],
    dhat: float,
) -> list[tuple[float, int, str, float]]:  # fmt: skip
    """Events ``(time s, shell, kind, centre-of-mass height m)`` of the step, from the :func:`end`
    of its ``before`` and ``after`` ends."""
    (z0, w0, gap0), (z1, w1, gap1) = before, after
    out = []
    if w0 > 0.0 >= w1:
        s = apex_fraction(z0, z1, h * w0, h * w1)
        out.append((t + s * h, shell, "apex", hermite(z0, z1, h * w0, h * w1, s)))
    g0, g1 = gap0 - dhat, gap1 - dhat
    if (g0 >= 0.0) != (g1 >= 0.0):
        s = g0 / (g0 - g1)
        kind = "touchdown" if g1 < 0.0 else "liftoff"
        out.append((t + s * h, shell, kind, hermite(z0, z1, h * w0, h * w1, s)))
    return out
