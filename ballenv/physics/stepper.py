"""Implicit time step, Newton loop, step rejection and step-size control.

Unknown of a step of size ``h``: the new node positions ``x1``. Backward Euler::

    v1 = (x1 - x0) / h,   M (v1 - v0) / h = F(x1, v1)

Generalized-alpha (Chung & Hulbert 1993; Newmark update with ``beta``, ``gamma``)::

    a1 = (x1 - x0 - h v0) / (beta h^2) - (1/2 - beta) / beta a0
    v1 = v0 + h ((1 - gamma) a0 + gamma a1)
    M ((1 - alpha_m) a1 + alpha_m a0) = F((1 - alpha_f) x1 + alpha_f x0, (1 - alpha_f) v1 + alpha_f v0)

Both give a residual ``r(x1) = M * inertia - F`` whose exact Jacobian is
``c_M M - c_x dF/dx - c_v dF/dv``, solved in O(N) by :func:`linalg.solve_band_low_rank`. The
iteration stops when the residual is small against the forces it balances,
``|r|_inf <= newton_tol * max_i (|M inertia_i| + |F_i|)``, or when a correction is at round-off level
(``|dx|_inf <= 1e-13 |x|_inf``); it fails (the step is rejected) on a non-finite value, a singular
system, or after ``newton_max_iter`` corrections. (A tolerance on positions alone would not do: an
error ``dx`` in ``x1`` is an error ``dx / h`` in velocity, which grows without bound as ``h -> 0``.)

A correction that does not lower ``|r|^2`` (Armijo, ``|r_new|^2 > (1 - 2e-4 lam) |r_old|^2``) or
gives a non-finite residual is halved, at most five times (backtracking line search). Full Newton
steps cycle on Coulomb friction: an arriving node's reaction makes ``mu N s(v_t)`` a near step
function of its slip (``mu v_n / eps`` ~ 150 at 3 m/s), independent of ``h``, so halving the time step
alone never recovered.
"""

import math

from numba import njit

from .collision import collision_impulses, collision_step_limit, rings_intrude, self_intersects
from .contact import FREE, constrain_jacobian, constrain_residual, deepest_ground
from .elastic import bend_force, bend_jacobian, stretch_force, stretch_jacobian
from .energy import ENERGY_GRAVITY, remove_internal_kinetic_energy, ring_energy
from .events import detect_events
from .linalg import solve_band_low_rank
from .loads import (
    DAMPING_NONE,
    damping_force,
    damping_jacobian,
    gas_pressure,
    gas_pressure_slope,
    gravity_force,
    polygon_area,
    pressure_force,
    pressure_jacobian,
)
from .model import CONTACT_MASS_MODIFICATION, CONTACT_NONE, METHOD_BACKWARD_EULER

STATUS_DONE = 0
STATUS_BUFFER_FULL = 1
STATUS_STEP_TOO_SMALL = 2
STATUS_IMPULSE_AT_DT_MIN = 3

# counters: accepted steps, rejected steps, Newton iterations (linear solves), fixed-grid index
COUNT_STEPS = 0
COUNT_REJECTED = 1
COUNT_NEWTON = 2
COUNT_GRID = 3
COUNT_RECORDS = 4
COUNT_EVENTS = 5
COUNT_REJECTION = 6  # why the last step was rejected: one of the REJECT_ codes
COUNT_BY_REASON = 7  # counters[COUNT_BY_REASON + code - 1]: rejected steps by REJECT_ code
COUNT_IMPULSE_REJECTED = 11  # adaptive steps rejected for a contact impulse above impulse_tol
COUNT_ENERGY_PROJECTED = 12  # accepted (step, ring) pairs whose energy gain was removed
N_COUNTERS = 13

# why a trial step was rejected (try_step returns minus the code)
REJECT_NEWTON = 1  # Newton's iteration failed (non-finite, singular, too many corrections)
REJECT_ENERGY = 2  # the step gained energy
REJECT_INTRUSION = 3  # a node of one ring ended inside another ring
REJECT_SELF_INTERSECTION = 4  # a ring's polygon crossed itself
REJECTION_REASONS = {
    REJECT_NEWTON: "Newton's iteration did not converge",
    REJECT_ENERGY: "the step gained energy (more than the energy budget can take back)",
    REJECT_INTRUSION: "a node of one ring ended inside another ring",
    REJECT_SELF_INTERSECTION: "a ring's wall crossed itself",
}

PENETRATION_TOLERANCE = -1e-12  # m: a free node deeper than this below a ground gets constrained
MAX_CONTACT_SET_CHANGES = 64
ENERGY_GROWTH_TOL = 1e-2  # largest energy gain of a step, relative to the ring's free energy
MIN_NEWTON_FRACTION = 1.0 / 32.0  # backtracking halves a correction at most 5 times

# columns of State.energy (J): a ring's energy, its free part (see free_energy) and its energy
# budget: the energy at the start plus what actuation and collision impulses gave it since
ENERGY_TOTAL = 0
ENERGY_FREE = 1
ENERGY_BUDGET = 2

# clock: time (s), current step size (s), energy removed by the energy budget so far (J), energy
# collision impulses created so far (J)
CLOCK_T = 0
CLOCK_H = 1
CLOCK_ENERGY_REMOVED = 2
CLOCK_COLLISION_GAIN = 3
N_CLOCK = 4

# Workspace.energy_tally of a trial step: rings whose energy the budget lowered, the energy it
# removed (J), the net energy the step's collision impulses created (J; 0 if they removed energy)
TALLY_PROJECTED = 0
TALLY_REMOVED = 1
TALLY_COLLISION_GAIN = 2


@njit(cache=True)
def ring_pressure(model, r, x):
    """Gauge pressure (Pa) of ring ``r`` with nodes ``x``; 0 for a ring without gas."""
    if not model.pressurised[r]:
        return 0.0
    return gas_pressure(
        polygon_area(x), model.gas_constant[r], model.gas_exponent, model.atmospheric_pressure
    )


@njit(cache=True)
def ring_force(model, r, x, v, f):
    """Total force (N) on the nodes of ring ``r``, written to ``f``; only the scene's effects."""
    f[:, :] = 0.0
    stretch_force(x, model.rest_len[r], model.ea[r], f)
    bend_force(x, model.rest_len[r], model.ei[r], model.rest_turn[r], f)
    if model.pressurised[r]:
        pressure_force(x, ring_pressure(model, r, x), model.width[r], f)
    if model.use_gravity:
        gravity_force(model.node_mass[r], model.gravity, f)
    if model.damping_mode != DAMPING_NONE:
        damping_force(x, v, model.node_mass[r], model.damping, model.damping_mode, f)


@njit(cache=True)
def free_energy(model, r, x, v, parts, out):
    """``out[ENERGY_TOTAL]`` = the energy (J) of ring ``r``; ``out[ENERGY_FREE]`` = its free part:
    kinetic plus elastic and gas energy above the inflated circle at rest (``Model.rest_energy``),
    gravity left out. Other columns of ``out`` are left alone."""
    out[ENERGY_TOTAL] = ring_energy(model, r, x, v, parts)
    out[ENERGY_FREE] = out[ENERGY_TOTAL] - parts[ENERGY_GRAVITY] - model.rest_energy[r]


@njit(cache=True)
def _energy_grew(total_before, free_before, total_after, free_after):
    """True if a step from energy ``total_before`` to ``total_after`` (J; ``free_``: their free
    parts, see :func:`free_energy`) raised the total by more than ``ENERGY_GROWTH_TOL`` times the
    mean free energy, or gave a non-finite energy."""
    if not math.isfinite(total_after):
        return True
    free = max(0.5 * (free_before + free_after), 0.0)
    return total_after - total_before > ENERGY_GROWTH_TOL * free + 1e-12 * abs(total_before)


@njit(cache=True)
def _energy_scale(model, r, x, parts):
    """Size (J) of the terms that make up ring ``r``'s energy, for round-off tolerances: the sum of
    |energy parts| ``parts`` (5,), with gravity's part taken node by node, ``m |g_d x_i,d|`` summed
    (the ring's gravity energy can cancel to nearly 0 while its nodes' terms do not)."""
    scale = 0.0
    for k in range(parts.shape[0]):
        if k != ENERGY_GRAVITY:
            scale += abs(parts[k])
    if model.use_gravity:
        for i in range(x.shape[0]):
            for d in range(2):
                scale += model.node_mass[r] * abs(model.gravity[d] * x[i, d])
    return scale


@njit(cache=True)
def _within_energy_budget(model, r, before, kick, trial, ws):
    """Hold ring ``r``'s energy after a trial step to its budget ``trial.energy[r, ENERGY_BUDGET]``
    (J): its energy at the start of the run plus what actuation and collision impulses gave it
    since. Nothing else in a scene adds energy: the gas and gravity are potentials; damping,
    friction and the ground's constraints only remove it. ``before`` is the ring's carried energy
    row before the step, ``kick`` the kinetic energy the step's collision impulses gave it.

    A gain of the step above ``ENERGY_GROWTH_TOL`` times the mean free energy is a spurious solution
    (far too large implicit steps of a nonlinear ring converge to some): returns False, the step is
    rejected and retried smaller. Smaller gains are the integrator's truncation error
    (generalized-alpha is not energy-stable for a nonlinear ring: the energy of a spinning ring
    oscillates by about ``h^2.5``); whatever of it lifts the energy above the budget is removed from
    the ring's velocities relative to its centre of mass, keeping its momentum
    (:func:`energy.remove_internal_kinetic_energy`), ``trial.energy[r]`` is recomputed and the
    removal is tallied in ``ws.energy_tally``; ground-constrained nodes are then put back at rest
    in their ground's normal direction (which only lowers the energy further). If the ring's spin
    and deformation hold too little kinetic energy to pay the excess (a ring in rigid translation),
    an excess within round-off (1e-12 of :func:`_energy_scale`) is accepted as it is and a larger
    one returns False. ``ws.energy`` must hold the energy parts of the trial state (as
    :func:`free_energy` leaves them)."""
    after = trial.energy[r]
    if _energy_grew(
        before[ENERGY_TOTAL] + kick, before[ENERGY_FREE] + kick, after[ENERGY_TOTAL], after[ENERGY_FREE]
    ):
        return False
    excess = after[ENERGY_TOTAL] - after[ENERGY_BUDGET]
    if excess <= 0.0:
        return True
    if not remove_internal_kinetic_energy(trial.x[r], trial.v[r], model.node_mass[r], excess):
        return excess <= 1e-12 * _energy_scale(model, r, trial.x[r], ws.energy)
    _rest_on_grounds(model.grounds, trial.active[r], trial.v[r], trial.a[r])
    free_energy(model, r, trial.x[r], trial.v[r], ws.energy, after)
    ws.energy_tally[TALLY_PROJECTED] += 1.0
    ws.energy_tally[TALLY_REMOVED] += excess
    return True


@njit(cache=True)
def ring_jacobian(model, r, x, v, c_mass, c_x, c_v, ws):
    """Assemble ``c_M M - c_x dF/dx - c_v dF/dv`` as band ``ws.band`` + ``ws.u ws.w^T``; return rank."""
    band = ws.band
    pos = ws.pos
    band[:, :] = 0.0
    n = x.shape[0]
    diag = c_mass * model.node_mass[r]
    w = (band.shape[1] - 1) // 2
    for i in range(n):
        p = 2 * pos[i]
        band[p, w] += diag
        band[p + 1, w] += diag
    stretch_jacobian(x, model.rest_len[r], model.ea[r], -c_x, band, pos)
    bend_jacobian(x, model.rest_len[r], model.ei[r], model.rest_turn[r], -c_x, band, pos)
    rank = 0
    if model.pressurised[r]:
        area = polygon_area(x)
        p = gas_pressure(area, model.gas_constant[r], model.gas_exponent, model.atmospheric_pressure)
        slope = gas_pressure_slope(area, model.gas_constant[r], model.gas_exponent)
        rank = pressure_jacobian(x, p, slope, model.width[r], -c_x, band, pos, ws.u, ws.w, rank)
    if model.damping_mode != DAMPING_NONE:
        rank = damping_jacobian(
            x,
            v,
            model.node_mass[r],
            model.damping,
            model.damping_mode,
            -c_x,
            -c_v,
            band,
            pos,
            ws.u,
            ws.w,
            rank,
        )
    return rank


@njit(cache=True)
def _kinematics(solver, x0, v0, a0, h, x1, v1, a1, ws):
    """From the step's displacement ``ws.dx``: ``x1``, ``v1``, ``a1`` and the force evaluation point
    ``ws.xe``, ``ws.ve``. Working with the displacement (not ``x1``) keeps ``a1`` free of the
    cancellation ``x1 - x0``, whose round-off would grow like ``1 / h^2``."""
    n = x1.shape[0]
    dx = ws.dx
    if solver.method == METHOD_BACKWARD_EULER:
        for i in range(n):
            for d in range(2):
                x1[i, d] = x0[i, d] + dx[i, d]
                v1[i, d] = dx[i, d] / h
                a1[i, d] = (dx[i, d] - h * v0[i, d]) / (h * h)
                ws.xe[i, d] = x1[i, d]
                ws.ve[i, d] = v1[i, d]
    else:
        beta = solver.beta
        gamma = solver.gamma
        af = solver.alpha_f
        for i in range(n):
            for d in range(2):
                x1[i, d] = x0[i, d] + dx[i, d]
                a1[i, d] = (dx[i, d] - h * v0[i, d]) / (beta * h * h) - (0.5 - beta) / beta * a0[i, d]
                v1[i, d] = v0[i, d] + h * ((1.0 - gamma) * a0[i, d] + gamma * a1[i, d])
                ws.xe[i, d] = x0[i, d] + (1.0 - af) * dx[i, d]
                ws.ve[i, d] = (1.0 - af) * v1[i, d] + af * v0[i, d]


@njit(cache=True)
def _predict(solver, v0, a0, h, dx):
    for i in range(dx.shape[0]):
        for d in range(2):
            dx[i, d] = h * v0[i, d]
            if solver.method != METHOD_BACKWARD_EULER:
                dx[i, d] += 0.5 * h * h * a0[i, d]


@njit(cache=True)
def _activate_penetrating(grounds, active, x1, only_deeper_than):
    """Constrain free nodes below a ground; returns True if any was added."""
    changed = False
    for i in range(active.shape[0]):
        if active[i] == FREE:
            g, phi = deepest_ground(grounds, x1[i, 0], x1[i, 1])
            if phi < only_deeper_than:
                active[i] = g
                changed = True
    return changed


@njit(cache=True)
def _rest_on_grounds(grounds, active, v1, a1):
    """A constrained node ends the step at rest in the ground's normal direction (normal velocity
    and algorithmic acceleration zeroed): it sits on the surface. Without this, backward Euler's
    ``v1 = (x1 - x0) / h`` leaves a node that arrived from a gap a velocity into the ground, and the
    Newmark update of generalized-alpha reflects it and leaves an acceleration spike that the alpha_m
    term feeds back into the next steps (the known weakness of Newmark schemes with contact)."""
    for i in range(active.shape[0]):
        g = active[i]
        if g == FREE:
            continue
        nx, ny = grounds[g, 0], grounds[g, 1]
        vn = v1[i, 0] * nx + v1[i, 1] * ny
        an = a1[i, 0] * nx + a1[i, 1] * ny
        v1[i, 0] -= vn * nx
        v1[i, 1] -= vn * ny
        a1[i, 0] -= an * nx
        a1[i, 1] -= an * ny


@njit(cache=True)
def mass_coefficients(solver, h):
    """``(c_M, c_x, c_v, alpha_m)`` of a step ``h`` (s): the Jacobian is ``c_M M - c_x dF/dx - c_v
    dF/dv``; a constant extra force ``F`` moves a free node of mass ``m`` by ``F / (c_M m)``."""
    if solver.method == METHOD_BACKWARD_EULER:
        return 1.0 / (h * h), 1.0, 1.0 / h, 0.0
    c_x = 1.0 - solver.alpha_f
    c_mass = (1.0 - solver.alpha_m) / (solver.beta * h * h)
    c_v = c_x * solver.gamma / (solver.beta * h)
    return c_mass, c_x, c_v, solver.alpha_m


@njit(cache=True)
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
    reactions. Returns the number of Newton corrections (>= 0), or -1 if the step must be rejected.
    """
    n = x0.shape[0]
    m = model.node_mass[r]
    c_mass, c_x, c_v, am = mass_coefficients(solver, h)
    contact = model.contact_method != CONTACT_NONE
    inner_updates = model.contact_method == CONTACT_MASS_MODIFICATION
    set_changes = 0
    dx = ws.dx
    _predict(solver, v0, a0, h, dx)
    if contact and inner_updates:
        _kinematics(solver, x0, v0, a0, h, x1, v1, a1, ws)
        if _activate_penetrating(model.grounds, active, x1, PENETRATION_TOLERANCE):
            set_changes += 1
    res = ws.res
    f = ws.force
    delta = ws.delta
    total = 0
    settled = False
    it = 0
    merit_before = math.inf  # |r|^2 where the last correction started
    lam = 1.0  # fraction of the last correction applied
    while True:
        _kinematics(solver, x0, v0, a0, h, x1, v1, a1, ws)
        ring_force(model, r, ws.xe, ws.ve, f)
        worst = 0.0
        scale = 0.0
        finite = True
        for i in range(n):
            for d in range(2):
                inertia = m * ((1.0 - am) * a1[i, d] + am * a0[i, d])
                val = inertia - f[i, d]
                res[2 * i + d] = val
                finite = finite and math.isfinite(val)
                scale = max(scale, abs(inertia) + abs(f[i, d]))
        merit = math.inf  # |r|^2
        if finite:
            if contact:
                constrain_residual(
                    model.grounds, active, x1, ws.ve, res, m, c_mass, model.friction_regularization,
                    ws.reaction, ws.friction,
                )  # fmt: skip
            merit = 0.0
            for k in range(2 * n):
                worst = max(worst, abs(res[k]))
                merit += res[k] * res[k]
        elif lam <= MIN_NEWTON_FRACTION or merit_before == math.inf:
            return -1
        worse = merit > (1.0 - 2e-4 * lam) * merit_before
        if (not finite or not settled) and worse and lam > MIN_NEWTON_FRACTION:
            lam *= 0.5  # backtrack: take back half of what is left of the last correction
            for i in range(n):
                for d in range(2):
                    dx[i, d] += lam * delta[i, d]
            continue
        if settled or worst <= solver.newton_tol * scale:
            if not contact:
                return total
            changed = False
            for i in range(n):
                if active[i] != FREE and ws.reaction[i] < 0.0:
                    active[i] = FREE
                    changed = True
            if _activate_penetrating(model.grounds, active, x1, PENETRATION_TOLERANCE):
                changed = True
            if not changed:
                _rest_on_grounds(model.grounds, active, v1, a1)
                return total
            set_changes += 1
            if set_changes > MAX_CONTACT_SET_CHANGES:
                return -1
            settled = False
            it = 0
            merit_before = math.inf
            if not inner_updates:
                _predict(solver, v0, a0, h, dx)
            continue  # the residual's rows changed with the set
        if it >= solver.newton_max_iter:
            return -1
        rank = ring_jacobian(model, r, ws.xe, ws.ve, c_mass, c_x, c_v, ws)
        if contact:
            constrain_jacobian(
                model.grounds, active, ws.ve, ws.reaction, ws.band, ws.pos, ws.u, rank, m, c_mass,
                c_v, model.friction_regularization,
            )  # fmt: skip
        if not solve_band_low_rank(ws.band, ws.pos, ws.u, ws.w, rank, res, ws.work, ws.cap, ws.coef):
            return -1
        total += 1
        it += 1
        merit_before = merit
        lam = 1.0
        step = 0.0
        size = 0.0
        for i in range(n):
            for d in range(2):
                correction = res[2 * i + d]
                if not math.isfinite(correction):
                    return -1
                delta[i, d] = correction
                dx[i, d] -= correction
                step = max(step, abs(correction))
                size = max(size, abs(x0[i, d]) + abs(dx[i, d]))
        settled = step <= 1e-13 * size


@njit(cache=True)
def initial_state_values(model, solver, state, ws):
    """Fill what the stepper carries besides ``x, v``: every ring's energy (its budget = its energy
    now) and, for generalized-alpha, its start acceleration."""
    for r in range(state.x.shape[0]):
        free_energy(model, r, state.x[r], state.v[r], ws.energy, state.energy[r])
        state.energy[r, ENERGY_BUDGET] = state.energy[r, ENERGY_TOTAL]
    if solver.method != METHOD_BACKWARD_EULER:
        initial_acceleration(model, state.x, state.v, state.a, ws)


@njit(cache=True)
def initial_acceleration(model, x, v, a, ws):
    """``a = F(x, v) / m`` for every ring (the generalized-alpha start value)."""
    for r in range(x.shape[0]):
        ring_force(model, r, x[r], v[r], ws.force)
        for i in range(x.shape[1]):
            for d in range(2):
                a[r, i, d] = ws.force[i, d] / model.node_mass[r]


@njit(cache=True)
def try_step(model, solver, state, trial, h, ws):
    """One step of every ring from ``state`` into ``trial``.

    Returns (Newton corrections, contact impulse in N s), or (-code, 0) if the step must be rejected,
    with ``code`` one of the ``REJECT_`` reasons: a ring's Newton iteration failed, a ring gained
    energy beyond what :func:`_within_energy_budget` removes, a ring crossed itself
    (``model.reject_self_intersection``), or a node of one ring ended inside another
    (``model.collide``).

    The contact impulse is the largest over rings of
    ``|h sum_i f_i + kappa sum_i m min(0, v_n,i + gap_i / h) n|``: the ring's total ground reaction
    impulse over the step (its momentum change by contact, the paper's ``f dt``) less the reaction
    that stops the constrained nodes' start velocity into their ground (normal velocity ``v_n < 0``
    and distance ``gap`` at the step's start: nodes arriving in this step, and resting nodes that a
    collision impulse pushed into the ground). Such a node loses its normal momentum in whatever
    step it happens (a point mass hitting a rigid wall), so no step size could bring that part under
    a tolerance; the remainder grows with ``h`` and is what the step-size control bounds. The same
    holds for the Coulomb friction on such a node while it is stopped, at most ``mu`` times that
    normal impulse: its tangential impulse is counted only above ``mu kappa m |v_n + gap / h|``
    (without this, a sliding impact left a floor ``mu m v_n`` per arriving node that no step size
    could bring under ``impulse_tol``). ``kappa`` is
    the integrator's reaction to an arrival per unit momentum: 1 for backward Euler,
    ``(1 - alpha_m) / beta`` for generalized-alpha (whose Newmark update reflects the node's normal
    velocity before :func:`_rest_on_grounds` removes it).

    With ring collision, the collision impulses are found on the predicted positions ``x0 + h v0``
    and added to the start velocities (``collision.py``); each ring's energy guard and energy budget
    are credited with the change of its kinetic energy by them. Their sum over rings is negative
    (energy lost) except where they push out nodes that start the step inside the contact distance
    (a Baumgarte-type term): that net gain is tallied in ``ws.energy_tally``. They are not part of
    the contact impulse (the part that stops an approaching node does not shrink with the step).
    """
    total = 0
    impulse = 0.0
    ws.energy_tally[:] = 0.0
    contact = model.contact_method != CONTACT_NONE
    cw = ws.collision
    v0 = state.v
    kicks = model.collide or model.reject_self_intersection
    if kicks:
        v0 = cw.kicked
        collision_impulses(
            state.x, state.v, h, model.thickness, model.node_mass, model.collide,
            model.reject_self_intersection, cw, v0, cw.kinetic_change,
        )  # fmt: skip
        created = 0.0
        for r in range(state.x.shape[0]):
            created += cw.kinetic_change[r]
        ws.energy_tally[TALLY_COLLISION_GAIN] = max(0.0, created)
    for r in range(state.x.shape[0]):
        trial.active[r] = state.active[r]
        its = newton_ring(
            model, solver, r, state.x[r], v0[r], state.a[r], h, trial.x[r], trial.v[r],
            trial.a[r], ws, trial.active[r],
        )  # fmt: skip
        if its < 0:
            return -REJECT_NEWTON, 0.0
        if model.reject_self_intersection and self_intersects(trial.x[r]):
            return -REJECT_SELF_INTERSECTION, 0.0
        free_energy(model, r, trial.x[r], trial.v[r], ws.energy, trial.energy[r])
        kick = cw.kinetic_change[r] if kicks else 0.0
        trial.energy[r, ENERGY_BUDGET] = state.energy[r, ENERGY_BUDGET] + kick
        if not _within_energy_budget(model, r, state.energy[r], kick, trial, ws):
            return -REJECT_ENERGY, 0.0
        total += its
        if contact:
            m = model.node_mass[r]
            if solver.method != METHOD_BACKWARD_EULER:
                m *= (1.0 - solver.alpha_m) / solver.beta
            jx = 0.0
            jy = 0.0
            for i in range(state.x.shape[1]):
                g = trial.active[r, i]
                if g == FREE:
                    trial.contact_force[r, i, 0] = 0.0
                    trial.contact_force[r, i, 1] = 0.0
                    continue
                nx, ny = model.grounds[g, 0], model.grounds[g, 1]
                fn, ft = ws.reaction[i], ws.friction[i]
                fx = fn * nx - ft * ny
                fy = fn * ny + ft * nx
                trial.contact_force[r, i, 0] = fx
                trial.contact_force[r, i, 1] = fy
                jx += h * fx
                jy += h * fy
                # the reaction that stops the node's start velocity into the surface (an arriving
                # node, or a resting one pushed by a collision impulse): kappa m (v_n + gap / h)
                gap = max(0.0, nx * state.x[r, i, 0] + ny * state.x[r, i, 1] - model.grounds[g, 2])
                vn = min(0.0, v0[r, i, 0] * nx + v0[r, i, 1] * ny + gap / h)
                if vn < 0.0:
                    jx += m * vn * nx
                    jy += m * vn * ny
                    # and the friction that comes with it, at most mu times that normal impulse
                    jt = h * ft
                    kept = math.copysign(max(0.0, abs(jt) - model.grounds[g, 3] * m * -vn), jt)
                    jx += (jt - kept) * ny  # the tangent is (-n_y, n_x)
                    jy -= (jt - kept) * nx
            impulse = max(impulse, math.sqrt(jx * jx + jy * jy))
    if model.collide and rings_intrude(trial.x, model.thickness, cw):
        return -REJECT_INTRUSION, 0.0
    return total, impulse


@njit(cache=True)
def _record(model, k, t, state, rec):
    rec.t[k] = t
    rec.x[k] = state.x
    rec.v[k] = state.v
    rec.contact_force[k] = state.contact_force
    for r in range(state.x.shape[0]):
        rec.pressure[k, r] = ring_pressure(model, r, state.x[r])


@njit(cache=True)
def _accept(state, trial):
    state.x[:] = trial.x
    state.v[:] = trial.v
    state.a[:] = trial.a
    state.active[:] = trial.active
    state.contact_force[:] = trial.contact_force
    state.energy[:] = trial.energy


@njit(cache=True)
def advance(model, solver, ws, state, trial, clock, counters, t_pause, t_end, output_dt, rec):
    """Step ``state`` from ``clock[CLOCK_T]`` to ``t_end``, pausing (returning) after the first step
    that reaches ``t_pause`` (<= ``t_end``; for progress reports).

    Records into ``rec`` from index ``counters[COUNT_RECORDS]`` on: every accepted step if
    ``output_dt == 0``, else exactly at multiples of ``output_dt`` (steps are shortened to land on
    them); events go to ``rec.events`` rows (t, ring, kind, centre-of-mass height). Returns
    STATUS_DONE, STATUS_BUFFER_FULL (call again with room), STATUS_STEP_TOO_SMALL (rejected steps
    halved the step below ``dt_min``; ``counters[COUNT_REJECTION]`` says why the last one was) or
    STATUS_IMPULSE_AT_DT_MIN (the contact impulse exceeds ``impulse_tol`` even at ``dt_min``); on
    failure the state is the last accepted one.

    Step control: a rejected step (see :func:`try_step`) is retried with half the step. With ring
    collision, every step is first kept within :func:`collision.collision_step_limit` (no node can
    cross more than half the contact distance toward another ring in it). Adaptive: with
    ground contact, a step whose contact impulse (see :func:`try_step`) exceeds ``impulse_tol`` is
    retried with ``h * max(0.2, 0.9 tol / (f h))``; accepted steps grow by ``min(growth, 1 + (ratio -
    1) / 2)`` (cautious), up to ``dt``.
    """
    capacity = rec.t.shape[0]
    n_rings = state.x.shape[0]
    while clock[CLOCK_T] < t_pause:
        if counters[COUNT_RECORDS] >= capacity or counters[COUNT_EVENTS] + 3 * n_rings > rec.events.shape[0]:
            return STATUS_BUFFER_FULL
        if model.collide:
            limit = collision_step_limit(state.x, state.v, model.thickness, clock[CLOCK_H], ws.collision)
            clock[CLOCK_H] = max(min(clock[CLOCK_H], limit), solver.dt_min)
        t = clock[CLOCK_T]
        eps = 1e-9 * solver.dt
        stop = t + clock[CLOCK_H]
        next_out = t_end
        if output_dt > 0.0:
            next_out = (math.floor((t + eps) / output_dt) + 1.0) * output_dt
            stop = min(stop, next_out)
        grid = (counters[COUNT_GRID] + 1) * solver.dt
        if not solver.adaptive:
            stop = min(stop, grid)
        stop = min(stop, t_end)
        at_end = stop >= t_end - eps
        at_out = output_dt > 0.0 and abs(stop - next_out) <= eps
        at_grid = not solver.adaptive and abs(stop - grid) <= eps
        if at_end:
            stop = t_end
        h = stop - t
        its, impulse = try_step(model, solver, state, trial, h, ws)
        if its < 0:
            counters[COUNT_REJECTION] = -its
            counters[COUNT_BY_REASON - its - 1] += 1
            counters[COUNT_REJECTED] += 1
            clock[CLOCK_H] = 0.5 * h
            if clock[CLOCK_H] < solver.dt_min:
                return STATUS_STEP_TOO_SMALL
            continue
        counters[COUNT_NEWTON] += its
        ratio = math.inf if impulse == 0.0 else model.impulse_tol / impulse
        if solver.adaptive and ratio < 1.0:
            if h <= 1.001 * solver.dt_min:  # (h = stop - t carries round-off)
                return STATUS_IMPULSE_AT_DT_MIN
            counters[COUNT_REJECTED] += 1
            counters[COUNT_IMPULSE_REJECTED] += 1
            clock[CLOCK_H] = max(solver.dt_min, h * max(0.2, 0.9 * ratio))
            continue
        counters[COUNT_STEPS] += 1
        counters[COUNT_ENERGY_PROJECTED] += int(ws.energy_tally[TALLY_PROJECTED])
        clock[CLOCK_ENERGY_REMOVED] += ws.energy_tally[TALLY_REMOVED]
        clock[CLOCK_COLLISION_GAIN] += ws.energy_tally[TALLY_COLLISION_GAIN]
        counters[COUNT_EVENTS] = detect_events(model, state, trial, t, h, rec.events, counters[COUNT_EVENTS])
        _accept(state, trial)
        clock[CLOCK_T] = stop
        if solver.adaptive:
            growth = min(solver.growth, max(1.0, 1.0 + 0.5 * (ratio - 1.0)))
            clock[CLOCK_H] = min(max(h, clock[CLOCK_H]) * growth, solver.dt)
        elif at_grid:
            counters[COUNT_GRID] += 1
            clock[CLOCK_H] = solver.dt
        if output_dt == 0.0 or at_out or at_end:
            _record(model, counters[COUNT_RECORDS], stop, state, rec)
            counters[COUNT_RECORDS] += 1
    return STATUS_DONE
