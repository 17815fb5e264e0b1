"""Newton's iteration of one ring's implicit step, with the ground's contact set.

The integrator (:mod:`.integrator`) turns the step's displacement ``dx`` into ``x1, v1, a1``; the
residual ``r(dx) = M ((1 - alpha_m) a1 + alpha_m a0) - F`` sums the effects' forces
(:func:`assembly.ring_force`), with the rows of ground-constrained nodes replaced
(:mod:`.contact`). Its exact Jacobian ``c_M M - c_x dF/dx - c_v dF/dv`` is a band plus low-rank
columns, solved in O(N) (:func:`linalg.solve_band_low_rank`). The iteration stops when the residual
is small against the forces it balances, ``|r|_inf <= newton_tol * max_i (|M inertia_i| + |F_i|)``,
or when a correction is at round-off level (``|dx|_inf <= 1e-13 |x|_inf``); it fails (the step is
rejected) on a non-finite value, a singular system, or after ``newton_max_iter`` corrections. (A
tolerance on positions alone would not do: an error ``dx`` in ``x1`` is an error ``dx / h`` in
velocity, which grows without bound as ``h -> 0``.)

A correction that does not lower ``|r|^2`` (Armijo, ``|r_new|^2 > (1 - 2e-4 lam) |r_old|^2``) or
gives a non-finite residual is halved, at most five times (backtracking line search). Full Newton
steps cycle on Coulomb friction: an arriving node's reaction makes ``mu N s(v_t)`` a near step
function of its slip (``mu v_n / eps`` ~ 150 at 3 m/s), independent of ``h``, so halving the time step
alone does not recover.
"""

import math

from .assembly import ring_force, ring_jacobian
from .contact import (
    FREE,
    PENETRATION_TOLERANCE,
    activate_penetrating,
    constrain_jacobian,
    constrain_residual,
    rest_on_grounds,
)
from .integrator import coefficients, kinematics, predict
from .jit import kernel
from .linalg import solve_band_low_rank
from .model import CONTACT_MASS_MODIFICATION, CONTACT_NONE

MAX_CONTACT_SET_CHANGES = 64
MIN_NEWTON_FRACTION = 1.0 / 32.0  # backtracking halves a correction at most 5 times
FAILED = -1


@kernel(inline="always")
def residual(model, solver, r, x0, v0, a0, h, x1, v1, a1, ws, active):
    """The residual of the iterate ``ws.dx`` into ``ws.res`` (and ``x1, v1, a1``); returns
    ``(|r|^2, |r|_inf, force scale, finite)``: ``|r|^2`` is inf when a value is not finite."""
    n = x0.shape[0]
    m = model.node_mass[r]
    c_mass, _, _, am = coefficients(solver, h)
    kinematics(solver, x0, v0, a0, h, x1, v1, a1, ws)
    ring_force(model, r, ws.xe, ws.ve, ws.force)
    res = ws.res
    f = ws.force
    scale = 0.0
    finite = True
    for i in range(n):
        for d in range(2):
            inertia = m * ((1.0 - am) * a1[i, d] + am * a0[i, d])
            val = inertia - f[i, d]
            res[2 * i + d] = val
            finite = finite and math.isfinite(val)
            scale = max(scale, abs(inertia) + abs(f[i, d]))
    if not finite:
        return math.inf, 0.0, scale, False
    if model.contact_method != CONTACT_NONE:
        constrain_residual(
            model.grounds, active, x1, ws.ve, res, m, c_mass, model.friction_regularization,
            ws.reaction, ws.friction,
        )  # fmt: skip
    merit = 0.0
    worst = 0.0
    for k in range(2 * n):
        worst = max(worst, abs(res[k]))
        merit += res[k] * res[k]
    return merit, worst, scale, True


@kernel(inline="always")
def correction(model, solver, r, x0, h, ws, active):
    """Solve the Newton system at the iterate and apply the correction to ``ws.dx`` (kept in
    ``ws.delta`` for backtracking). Returns ``(ok, settled)``: ok False on a singular system or a
    non-finite correction; settled when the correction is at round-off level."""
    n = x0.shape[0]
    m = model.node_mass[r]
    c_mass, c_x, c_v, _ = coefficients(solver, h)
    rank = ring_jacobian(model, r, ws.xe, ws.ve, c_mass, c_x, c_v, ws)
    if model.contact_method != CONTACT_NONE:
        constrain_jacobian(
            model.grounds, active, ws.ve, ws.reaction, ws.band, ws.pos, ws.u, rank, m, c_mass,
            c_v, model.friction_regularization,
        )  # fmt: skip
    res = ws.res
    if not solve_band_low_rank(ws.band, ws.pos, ws.u, ws.w, rank, res, ws.work, ws.cap, ws.coef):
        return False, False
    dx = ws.dx  # (arrays taken out of the workspace once, not per element)
    delta = ws.delta
    step = 0.0
    size = 0.0
    for i in range(n):
        for d in range(2):
            c = res[2 * i + d]
            if not math.isfinite(c):
                return False, False
            delta[i, d] = c
            dx[i, d] -= c
            step = max(step, abs(c))
            size = max(size, abs(x0[i, d]) + abs(dx[i, d]))
    return True, step <= 1e-13 * size


@kernel(inline="always")
def update_contact_set(model, active, x1, reaction):
    """After convergence: free the constrained nodes whose normal reaction ``reaction`` (N) pulls,
    then constrain free nodes below a ground. Returns True if the set changed."""
    changed = False
    for i in range(active.shape[0]):
        if active[i] != FREE and reaction[i] < 0.0:
            active[i] = FREE
            changed = True
    if activate_penetrating(model.grounds, active, x1, PENETRATION_TOLERANCE):
        changed = True
    return changed


@kernel(inline="always")
def backtrack(ws, lam):
    """Take back the fraction ``lam`` of the last correction ``ws.delta`` from ``ws.dx``."""
    dx = ws.dx
    delta = ws.delta
    for i in range(dx.shape[0]):
        for d in range(2):
            dx[i, d] += lam * delta[i, d]


@kernel
def newton_ring(model, solver, r, x0, v0, a0, h, x1, v1, a1, ws, active):
    """Solve one implicit step of ring ``r``; ``x1, v1, a1`` receive the new state.

    ``active`` (N,) holds each node's constraining ground (or FREE) and is updated to the step's
    contact set. Once the iteration has converged, constraints whose reaction pulls are released and
    free nodes below a ground are constrained; then

    * mass-modification (Baraff & Witkin) also constrains the nodes whose predicted position is below
      a ground before the first iteration, and after a change goes on iterating from where it is
      (the system keeps its size; one solve usually absorbs the change);
    * predictor-corrector (the paper's method) recomputes the whole step from the predictor.

    The set is never changed from an unconverged iterate: far from the solution an iterate may swing
    nodes through a ground they never reach. ``ws.reaction``/``ws.friction`` receive the ground
    reactions. Returns the number of Newton corrections (>= 0), or ``FAILED`` (the step must be
    rejected).
    """
    contact = model.contact_method != CONTACT_NONE
    inner_updates = model.contact_method == CONTACT_MASS_MODIFICATION
    set_changes = 0
    predict(solver, v0, a0, h, ws.dx)
    if contact and inner_updates:
        kinematics(solver, x0, v0, a0, h, x1, v1, a1, ws)
        if activate_penetrating(model.grounds, active, x1, PENETRATION_TOLERANCE):
            set_changes += 1
    total = 0
    settled = False
    it = 0
    merit_before = math.inf  # |r|^2 where the last correction started
    lam = 1.0  # fraction of the last correction applied
    while True:
        merit, worst, scale, finite = residual(model, solver, r, x0, v0, a0, h, x1, v1, a1, ws, active)
        if not finite and (lam <= MIN_NEWTON_FRACTION or merit_before == math.inf):
            return FAILED
        worse = merit > (1.0 - 2e-4 * lam) * merit_before
        if (not finite or not settled) and worse and lam > MIN_NEWTON_FRACTION:
            lam *= 0.5  # backtrack: take back half of what is left of the last correction
            backtrack(ws, lam)
            continue
        if settled or worst <= solver.newton_tol * scale:
            if not contact:
                return total
            if not update_contact_set(model, active, x1, ws.reaction):
                rest_on_grounds(model.grounds, active, v1, a1)
                return total
            set_changes += 1
            if set_changes > MAX_CONTACT_SET_CHANGES:
                return FAILED
            settled = False
            it = 0
            merit_before = math.inf
            if not inner_updates:
                predict(solver, v0, a0, h, ws.dx)
            continue  # the residual's rows changed with the set
        if it >= solver.newton_max_iter:
            return FAILED
        ok, settled = correction(model, solver, r, x0, h, ws, active)
        if not ok:
            return FAILED
        total += 1
        it += 1
        merit_before = merit
        lam = 1.0
