"""The local error estimate of a step, which the error-controlled step size keeps below tolerance.

Each integrator's displacement over a step of size ``h`` (s) differs from the exact one by its
local truncation error. Its leading term follows from the accelerations at the step's two ends
(the difference quotient ``(a1 - a0) / h`` stands for the jerk)::

    backward Euler       e_i = h^2 a1_i / 2 = h (v1_i - v0_i) / 2   (x1 less the trapezoidal rule's)
    generalized-alpha    e_i = (beta - 1/6) h^2 (a1_i - a0_i)       (Zienkiewicz & Xie 1991)

in metres, per node ``i``.

Arrivals and departures at a ground are not smooth: the normal component of a node constrained at
either end of the step jumps whatever the step size (the contact criterion of the stepper bounds
that part), so it is left out of the estimate; the tangential part stays.

The error norm is the RMS over the ring's nodes of ``|e_i| / (atol + rtol R)`` with ``R`` the ring's
radius (m): a relative tolerance on positions that is translation-invariant, the ring's size being
its length scale. A step is accepted when the norm is at most 1; the next step is scaled by
``norm^(-1/(p+1))`` (``p`` = 1 for backward Euler, 2 for generalized-alpha; the estimate is
``O(h^(p+1))``). Each integrator's coefficients of the estimate live with it, in
:mod:`ballenv.physics.step.integrator`
(``error_coefficient``, ``error_start_weight``, ``error_exponent``).
"""

import math

from ..base.jit import kernel
from ..ground.contact import FREE, frame
from .integrator import error_coefficient, error_start_weight


@kernel
def _without_normal(grounds, g, x, ex, ey):
    """``(ex, ey)`` less its component along ground ``g``'s normal at the node's position ``x``
    (unchanged for ``FREE``)."""
    if g == FREE:
        return ex, ey
    nx, ny, _ = frame(grounds, g, x[0], x[1])
    en = ex * nx + ey * ny
    return ex - en * nx, ey - en * ny


@kernel
def error_norm(model, solver, r, h, x0, x1, a0, a1, active0, active1):
    """The scaled RMS local error of ring ``r``'s step of size ``h`` (s) from start and end
    accelerations ``a0``, ``a1`` (m/s^2, (N, 2); backward Euler's ``a1 = (v1 - v0) / h``) and the
    constraining grounds at both ends (nodes at ``x0``, ``x1``): at most 1 is within tolerance."""
    c = error_coefficient(solver) * h * h
    a0_weight = error_start_weight(solver)
    scale = solver.atol + solver.rtol * model.radius[r]
    total = 0.0
    n = a0.shape[0]
    for i in range(n):
        ex = c * (a1[i, 0] - a0_weight * a0[i, 0])
        ey = c * (a1[i, 1] - a0_weight * a0[i, 1])
        ex, ey = _without_normal(model.grounds, active0[i], x0[i], ex, ey)
        ex, ey = _without_normal(model.grounds, active1[i], x1[i], ex, ey)
        total += ex * ex + ey * ey
    return math.sqrt(total / n) / scale
