"""Newton's iteration of one ring's implicit step, with the ground's contact set.

The integrator (:mod:`ballenv.physics.step.integrator`) turns the step's displacement ``dx`` into ``x1, v1,
a1``; the residual ``r(dx) = M ((1 - alpha_m) a1 + alpha_m a0) - F`` sums the effects' forces
(:func:`effects.assembly.ring_force`), with the rows of ground-constrained nodes replaced
(:mod:`ballenv.physics.ground.contact`, on the grounds at the step's end, ``Workspace.surface``, which the
stepper fills). Its exact Jacobian ``c_M M - c_x dF/dx - c_v dF/dv`` is a band plus low-rank columns,
solved in O(N) (:func:`base.linalg.solve_band_low_rank`). The iteration stops when the residual is small
against the forces it balances, ``|r|_inf <= newton_tol * max_i (|M inertia_i| + |F_i|)``,
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

from ..base.jit import copy_into, kernel
from ..base.linalg import solve_band_low_rank, solve_band_wide_low_rank
from ..effects.assembly import ring_force, ring_jacobian
from ..ground.contact import (
    FREE,
    PENETRATION_TOLERANCE,
    activate_penetrating,
    constrain_jacobian,
    constrain_low_rank_rows,
    constrain_residual,
    rest_on_grounds,
)
from ..model import CONTACT_MASS_MODIFICATION, CONTACT_NONE
from ..walls.impulses import self_intersects
from ..walls.self_barrier import (
    CCD_SAFETY,
    barrier_force,
    barrier_jacobian,
    find_pairs,
    impact_fraction,
    near_pairs,
    reach,
    stiffness,
)
from ..walls.wall_limits import limit_fraction, wall_limit_force, wall_limit_jacobian
from .integrator import coefficients, kinematics, predict

MAX_CONTACT_SET_CHANGES = 64
PLAIN = 0  # Workspace.barrier.mode[0]: the step without the self-contact barrier
SAFE = 1  # with it, every correction filtered by continuous collision detection
COUPLED = 1  # Workspace.ring_contact.mode[0]: rings in contact solved jointly (else 0: one by one)
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
    if model.self_barrier:
        add_barrier_force(model, r, ws, ws.barrier)
        add_limit_force(model, r, ws, ws.barrier)
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
            ws.surface, active, x1, ws.ve, res, m, c_mass, model.friction_regularization,
            ws.reaction, ws.friction, ws.tangential,
        )  # fmt: skip
    merit = 0.0
    worst = 0.0
    for k in range(2 * n):
        worst = max(worst, abs(res[k]))
        merit += res[k] * res[k]
    return merit, worst, scale, True


@kernel(inline="always")
def correction(model, solver, r, x0, x1, h, ws, active):
    """Solve the Newton system at the iterate ``x1`` and apply the correction to ``ws.dx`` (kept in
    ``ws.delta`` for backtracking). Returns ``(ok, settled)``: ok False on a singular system or a
    non-finite correction; settled when the correction is at round-off level before the barrier's
    cut (a correction cut short by an impact ahead is not a converged one)."""
    n = x0.shape[0]
    m = model.node_mass[r]
    c_mass, c_x, c_v, _ = coefficients(solver, h)
    rank = ring_jacobian(model, r, ws.xe, ws.ve, c_mass, c_x, c_v, ws)
    wide = rank
    if model.self_barrier:
        add_limit_jacobian(model, r, c_x, ws, ws.barrier)
        wide = add_barrier_jacobian(model, r, c_x, ws, rank, ws.barrier)
    if model.contact_method != CONTACT_NONE:
        constrain_jacobian(
            ws.surface, active, x1, ws.ve, ws.reaction, ws.tangential, ws.band, ws.pos, ws.u, rank, m,
            c_mass, c_v, model.friction_regularization,
        )  # fmt: skip
        if wide > rank:
            constrain_barrier_rows(model, active, x1, ws, rank, wide, ws.barrier)
    res = ws.res
    if wide == rank:
        solved = solve_band_low_rank(ws.band, ws.pos, ws.u, ws.w, rank, res, ws.work, ws.cap, ws.coef)
    else:
        solved = solve_wide(ws, rank, wide, res, ws.barrier)
    if not solved:
        return False, False
    cut = 1.0
    if model.self_barrier:
        cut = barrier_filter(model, r, c_x, ws, res, ws.barrier)
        if cut < 0.0:
            return False, False
        cut = min(cut, limit_filter(c_x, ws.xe, x1, res, ws.barrier))
    dx = ws.dx  # (arrays taken out of the workspace once, not per element)
    delta = ws.delta
    step = 0.0
    size = 0.0
    for i in range(n):
        for d in range(2):
            c = res[2 * i + d] * cut
            if not math.isfinite(c):
                return False, False
            delta[i, d] = c
            dx[i, d] -= c
            step = max(step, abs(res[2 * i + d]))
            size = max(size, abs(x0[i, d]) + abs(dx[i, d]))
    return True, step <= 1e-13 * size


# The barrier's phases below are compiled functions (not inlined) that take the barrier's
# workspace ``bw`` as an argument: a scene without the barrier has ``Workspace.barrier = None``, and
# numba then prunes their bodies (``if bw is None``) before typing them, so the env and every scene
# without it compile and run none of the barrier's code.


@kernel
def add_barrier_jacobian(model, r, c_x, ws, rank, bw):
    """In safe mode, the barrier's Jacobian at ``ws.xe``: its near blocks into the band, its far
    couplings as low-rank columns ``rank ... wide - 1`` of ``bw.u, bw.w``. Returns ``wide``."""
    if bw is None:
        return rank
    if bw.mode[0] != SAFE or bw.n_pairs[0] == 0:
        return rank
    return barrier_jacobian(
        ws.xe, bw.pairs, bw.n_pairs[0], stiffness(model, r), reach(model, r), c_x, ws.band, ws.pos,
        bw.u, bw.w, rank, bw,
    )  # fmt: skip


@kernel
def constrain_barrier_rows(model, active, x1, ws, rank, wide, bw):
    """The ground constraints on the barrier's low-rank columns ``rank ... wide - 1``."""
    if bw is None:
        return
    constrain_low_rank_rows(ws.surface, active, x1, ws.ve, bw.u, rank, wide, model.friction_regularization)


@kernel
def solve_wide(ws, rank, wide, res, bw):
    """Solve the Newton system in place of ``res`` with the barrier's columns up to ``wide`` besides
    the effects' ``rank``: all of them by the wide solver. False without a barrier."""
    if bw is None:
        return False
    for k in range(res.shape[0]):
        for c in range(rank):
            bw.u[k, c] = ws.u[k, c]
            bw.w[k, c] = ws.w[k, c]
    return solve_band_wide_low_rank(ws.band, ws.pos, bw.u, bw.w, wide, res, ws.work, bw.z, bw.cap, bw.coef)


@kernel
def barrier_filter(model, r, c_x, ws, res, bw):
    """The fraction (in (0, 1]) of the correction ``-res`` to take so that no node meets an edge of
    its own ring on the way (:mod:`ballenv.physics.walls.self_barrier`): the candidate pairs over the motion
    of the force evaluation point ``ws.xe -> ws.xe - c_x res`` replace the barrier's pairs, and the first
    impact among them cuts the correction to ``CCD_SAFETY`` of it. Returns -1 if the pairs do not fit; 1
    outside safe mode."""
    if bw is None:
        return 1.0
    if bw.mode[0] != SAFE:
        return 1.0
    xe = ws.xe
    for i in range(xe.shape[0]):
        for d in range(2):
            bw.xn[i, d] = xe[i, d] - c_x * res[2 * i + d]
    return _cut_at_impact(model, r, xe, bw)


@kernel(inline="always")
def _cut_at_impact(model, r, xa, bw):
    """Candidate pairs over the motion ``xa -> bw.xn`` into ``bw.pairs``, ``bw.n_pairs``; the fraction
    of the motion before the first impact (``CCD_SAFETY`` of it, or 1), -1 if they do not fit."""
    count = find_pairs(xa, bw.xn, model.rest_len[r], reach(model, r), bw)
    bw.n_pairs[0] = max(count, 0)
    if count < 0:
        return -1.0
    if count == 0:
        return 1.0
    first = impact_fraction(xa, bw.xn, bw.pairs, count)
    return CCD_SAFETY * first if first <= 1.0 else 1.0


@kernel
def add_ring_contact_force(r, ws, rc):
    """In the joint step of rings in contact (``rc.mode[0] == COUPLED``), add ring ``r``'s share of
    the contact force between rings (``rc.force[r]``, N: :mod:`ballenv.physics.step.joint_newton`) to
    ``ws.force``."""
    if rc is None:
        return
    if rc.mode[0] != COUPLED:
        return
    f = ws.force
    for i in range(f.shape[0]):
        for d in range(2):
            f[i, d] += rc.force[r, i, d]


@kernel
def add_limit_force(model, r, ws, bw):
    """In either mode, add the wall limits' force (:mod:`ballenv.physics.walls.wall_limits`) at the force
    evaluation point ``ws.xe`` to ``ws.force`` (nothing unless a node folds or an edge collapses that far)."""
    if bw is None:
        return
    wall_limit_force(ws.xe, model.rest_len[r], model.ea[r], model.start_energy[r], ws.force)


@kernel
def add_limit_jacobian(model, r, c_x, ws, bw):
    """In either mode, add ``c_x`` times the wall limits' Hessian at ``ws.xe`` to the band."""
    if bw is None:
        return
    wall_limit_jacobian(ws.xe, model.rest_len[r], model.ea[r], model.start_energy[r], c_x, ws.band, ws.pos)


@kernel
def limit_filter(c_x, xe, x1, step, bw):
    """The fraction of the correction ``-step`` (2N,) that neither folds a node through nor collapses
    an edge (:func:`walls.wall_limits.limit_fraction`), over the motions of the force evaluation point
    ``xe -> xe - c_x step`` and of the step's end ``x1 -> x1 - step`` (the same motion for backward
    Euler); 1 if neither would."""
    if bw is None:
        return 1.0
    cut = 1.0
    for k in range(2 if c_x != 1.0 else 1):
        xa = xe if k == 0 else x1
        scale = c_x if k == 0 else 1.0
        for i in range(xa.shape[0]):
            for d in range(2):
                bw.xn[i, d] = xa[i, d] - scale * step[2 * i + d]
        cut = min(cut, limit_fraction(xa, bw.xn))
    return cut


@kernel
def add_barrier_force(model, r, ws, bw):
    """In safe mode, add the self-contact barrier's force at the force evaluation point ``ws.xe``
    (on the candidate pairs of the last correction's motion) to ``ws.force``; in the joint step of
    rings in contact, their contact force too (:func:`add_ring_contact_force`)."""
    if bw is None:
        return
    if bw.mode[0] == SAFE and bw.n_pairs[0] > 0:
        barrier_force(ws.xe, bw.pairs, bw.n_pairs[0], stiffness(model, r), reach(model, r), ws.force, bw)
    add_ring_contact_force(r, ws, ws.ring_contact)


@kernel
def barrier_start(model, solver, r, x0, h, ws, bw):
    """With the barrier: in safe mode, the candidate pairs over the predictor's motion (force
    evaluation point ``x0 -> x0 + c_x dx``) and the predictor cut before its first impact; in either
    mode, the predictor cut before it folds a node through or collapses an edge
    (:func:`walls.wall_limits.limit_fraction` over ``x0 -> x0 + dx``). False if the pairs do not fit."""
    if bw is None:
        return True
    if not model.self_barrier:
        return True
    _, c_x, _, _ = coefficients(solver, h)
    dx = ws.dx
    for i in range(x0.shape[0]):
        for d in range(2):
            bw.xn[i, d] = x0[i, d] + dx[i, d]  # the end's motion; the force point's is its first part
    cut = limit_fraction(x0, bw.xn)
    if bw.mode[0] == SAFE:
        for i in range(x0.shape[0]):
            for d in range(2):
                bw.xn[i, d] = x0[i, d] + c_x * dx[i, d]
        cut = min(cut, _cut_at_impact(model, r, x0, bw))
    if cut < 1.0:
        for i in range(x0.shape[0]):
            for d in range(2):
                dx[i, d] *= max(cut, 0.0)
    return cut >= 0.0


@kernel(inline="always")
def update_contact_set(surface, active, x1, reaction):
    """After convergence: free the constrained nodes whose normal reaction ``reaction`` (N) pulls,
    then constrain free nodes below a ground (``surface``: the grounds at the step's end). Returns
    True if the set changed."""
    changed = False
    for i in range(active.shape[0]):
        if active[i] != FREE and reaction[i] < 0.0:
            active[i] = FREE
            changed = True
    if activate_penetrating(surface, active, x1, PENETRATION_TOLERANCE):
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
def newton_ring(model, solver, r, x0, v0, a0, h, x1, v1, a1, ws, active, bw):
    """Solve one implicit step of ring ``r`` (:func:`newton_iterate`); ``x1, v1, a1`` receive the
    new state, ``active`` the step's contact set. Returns the number of Newton corrections (>= 0),
    or ``FAILED``. ``bw`` is the self-contact barrier's workspace (``ws.barrier``; None: a scene
    without the barrier, and numba then compiles only the plain step).

    With the self-contact barrier (``model.self_barrier``): a step that starts with no
    pair of the ring within ``dhat`` is first solved without it; if it ends with none either (or
    fails, or ends crossing itself: the stepper then rejects it and retries it smaller, until the
    wall parts meet within a step), that is the step, bit for bit the step without the barrier.
    Otherwise the step is solved in safe mode: the barrier acts, and the predictor and every
    correction are cut before their first impact (:func:`barrier_filter`), so no iterate passes a
    wall through another.
    """
    if bw is None:
        return newton_iterate(model, solver, r, x0, v0, a0, h, x1, v1, a1, ws, active)
    barrier = model.self_barrier
    rest_len = model.rest_len[r]
    dhat = reach(model, r) if barrier else 0.0
    safe = barrier and near_pairs(x0, rest_len, dhat, bw) > 0
    if barrier and not safe:
        bw.mode[0] = PLAIN
        copy_into(bw.active0, active)
    its = 0
    while True:  # one call of the inlined iteration: the plain try, then at most one safe solve
        if safe:
            bw.mode[0] = SAFE
        got = newton_iterate(model, solver, r, x0, v0, a0, h, x1, v1, a1, ws, active)
        if safe:
            return FAILED if got < 0 else got + its
        if not barrier or got < 0 or self_intersects(x1) or near_pairs(x1, rest_len, dhat, bw) == 0:
            return got
        copy_into(active, bw.active0)
        its = got
        safe = True


@kernel(inline="always")
def newton_iterate(model, solver, r, x0, v0, a0, h, x1, v1, a1, ws, active):
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
    reactions, ``ws.arrival_work[0]`` the work (J) a moving surface did by putting the constrained
    nodes at rest on it (:func:`ground.contact.rest_on_grounds`). Returns the number of Newton corrections
    (>= 0), or ``FAILED`` (the step must be rejected).
    """
    contact = model.contact_method != CONTACT_NONE
    inner_updates = model.contact_method == CONTACT_MASS_MODIFICATION
    set_changes = 0
    predict(solver, v0, a0, h, ws.dx)
    if not barrier_start(model, solver, r, x0, h, ws, ws.barrier):
        return FAILED
    if contact and inner_updates:
        kinematics(solver, x0, v0, a0, h, x1, v1, a1, ws)
        if activate_penetrating(ws.surface, active, x1, PENETRATION_TOLERANCE):
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
            if not update_contact_set(ws.surface, active, x1, ws.reaction):
                arrival = rest_on_grounds(ws.surface, active, x1, v1, a1)
                ws.arrival_work[0] = model.node_mass[r] * arrival
                return total
            set_changes += 1
            if set_changes > MAX_CONTACT_SET_CHANGES:
                return FAILED
            settled = False
            it = 0
            merit_before = math.inf
            if not inner_updates:
                predict(solver, v0, a0, h, ws.dx)
                if not barrier_start(model, solver, r, x0, h, ws, ws.barrier):
                    return FAILED
            continue  # the residual's rows changed with the set
        if it >= solver.newton_max_iter:
            return FAILED
        ok, settled = correction(model, solver, r, x0, x1, h, ws, active)
        if not ok:
            return FAILED
        total += 1
        it += 1
        merit_before = merit
        lam = 1.0
