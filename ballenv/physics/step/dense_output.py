"""Dense output: the recorded states at output times that fall inside an accepted step, interpolated
from the step's two ends, so that asking for records neither shortens steps nor changes the run.

Over a step from ``t0`` to ``t0 + h`` (s) with end states ``(x0, v0)`` and ``(x1, v1)`` (m, m/s), a
node free of every ground at both ends follows the cubic Hermite interpolant, with ``s = (t - t0) / h``:

    x(s) = h00 x0 + h10 h v0 + h01 x1 + h11 h v1,
    v(s) = (h00' x0 + h01' x1) / h + h10' v0 + h11' v1,
    h00 = 2 s^3 - 3 s^2 + 1,  h10 = s^3 - 2 s^2 + s,  h01 = -2 s^3 + 3 s^2,  h11 = s^3 - s^2

(``'`` = d/ds). It matches both ends' positions and velocities and is exact for motion of constant
acceleration (a flight parabola, whose ends the trapezoidal rule and generalized-alpha step exactly);
its error is O(h^4) in x for a smooth motion. A node on a ground at either end (arriving, resting
or leaving within the step) is interpolated linearly in x and v: the straight path between two
points above a half-plane stays above it, where the cubic can dip below the surface by up to
about ``0.15 h |v0|``. Contact forces (N) are interpolated linearly; the gas pressure (Pa) is that of
the interpolated polygon.
"""

import math

from ..base.jit import kernel
from ..effects.gas import ring_pressure
from ..ground.contact import FREE


@kernel(inline="always")
def outputs_within(t0, t1, output_dt, eps):
    """How many output times ``k output_dt`` (s) lie in ``(t0 + eps, t1 - eps)``: the records of
    a step from ``t0`` to ``t1`` between its ends."""
    first = math.floor((t0 + eps) / output_dt) + 1.0
    last = math.ceil((t1 - eps) / output_dt) - 1.0
    return max(0, int(last - first + 1.0))


@kernel(inline="always")
def hermite(s, h, p0, d0, p1, d1):
    """The cubic Hermite interpolant at ``s`` in [0, 1] of a step of ``h`` (s) from value ``p0``
    and rate ``d0`` to ``p1`` and ``d1``: ``(value, rate)``."""
    s2 = s * s
    s3 = s2 * s
    value = (2.0 * s3 - 3.0 * s2 + 1.0) * p0 + (s3 - 2.0 * s2 + s) * h * d0
    value += (3.0 * s2 - 2.0 * s3) * p1 + (s3 - s2) * h * d1
    rate = (6.0 * s2 - 6.0 * s) * (p0 - p1) / h + (3.0 * s2 - 4.0 * s + 1.0) * d0 + (3.0 * s2 - 2.0 * s) * d1
    return value, rate


@kernel
def interpolated_record(model, k, t, s, h, start, end, rec):
    """Record ``k`` of ``rec`` at time ``t`` (s), a fraction ``s`` of the way through a step of
    ``h`` (s) from state ``start`` to ``end`` (see the module doc)."""
    rec.t[k] = t
    for r in range(start.x.shape[0]):
        for i in range(start.x.shape[1]):
            linear = start.active[r, i] != FREE or end.active[r, i] != FREE
            for d in range(2):
                x0, x1 = start.x[r, i, d], end.x[r, i, d]
                v0, v1 = start.v[r, i, d], end.v[r, i, d]
                if linear:
                    rec.x[k, r, i, d] = x0 + s * (x1 - x0)
                    rec.v[k, r, i, d] = v0 + s * (v1 - v0)
                else:
                    rec.x[k, r, i, d], rec.v[k, r, i, d] = hermite(s, h, x0, v0, x1, v1)
                f0, f1 = start.contact_force[r, i, d], end.contact_force[r, i, d]
                rec.contact_force[k, r, i, d] = f0 + s * (f1 - f0)
        rec.pressure[k, r] = ring_pressure(model, r, rec.x[k, r])


@kernel
def record_within(model, start, end, t0, h, output_dt, eps, rec, k):
    """Records of the output times inside the accepted step from ``start`` at ``t0`` (s) to ``end``
    at ``t0 + h`` from index ``k`` on (:func:`outputs_within`); returns the next free index."""
    t1 = t0 + h
    first = math.floor((t0 + eps) / output_dt) + 1.0
    for j in range(outputs_within(t0, t1, output_dt, eps)):
        t = (first + j) * output_dt
        interpolated_record(model, k, t, (t - t0) / h, h, start, end, rec)
        k += 1
    return k
