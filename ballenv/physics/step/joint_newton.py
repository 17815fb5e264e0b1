"""Joint Newton iteration of the implicit step of rings in contact through the barrier.

The unknowns are every ring's step displacement ``dx_r``; the residual of ring ``r`` is its own
(:func:`step.newton.residual`: its effects, its self-contact barrier and wall limits, its grounds)
plus the contact force between rings (:mod:`ballenv.physics.walls.ring_barrier`) at the step's end
``x1``, like the grounds' constraints (for backward Euler the force evaluation point itself:
generalized-alpha's force point ``x0 + (1 - alpha_f) dx`` lies inside the step, and a barrier
evaluated there would let the step's end run into the contact distance unopposed). Its Hessian
enters with the coefficient 1 (``d x1 / d dx``). The Jacobian is block diagonal, one ring's Newton
matrix ``A_r`` (band plus low-rank columns, its grounds' row combinations) per block, plus the
pairs' Hessian blocks: those within one ring go into ``A_r``'s band, those between rings are the
rows of the ``K`` coupled nodes, ``C = E W^T`` (``E``: two unit columns per coupled node, through
its ground's row combination when constrained; ``W``: the rows' entries in the other rings'
unknowns). The joint system ``(D + E W^T) x = r`` is solved by the Woodbury identity without a dense
matrix of the unknowns::

    x = y - Z (I + W^T Z)^-1 W^T y,   y = D^-1 r,  Z = D^-1 E,

ring by ring: ``A_r^-1 [r_r, E_r]`` is one band factorisation and the ring's own Woodbury
(:func:`base.linalg.solve_band_low_rank_columns`); ``W^T Z`` sums over the entries of ``W`` (16 per
pair). Cost per Newton correction ``O(sum_r N w^2 + N (w + k_r) (1 + 2 K_r) + n_W 2K + (2K)^3)``
(``w`` the band's half-width, ``k_r`` ring ``r``'s low-rank columns, ``K_r`` its coupled nodes,
``n_W`` the entries): linear in the nodes, cubic only in the few nodes in contact.

Line search filter: the predictor and every correction are straight motions of the force evaluation
point and of the step's end; continuous collision detection over the pairs of different rings
(:func:`walls.ring_barrier.impact_fraction`) and each ring's own (:func:`step.newton.barrier_filter`,
:func:`step.newton.limit_filter`) cuts them all by one fraction, ``CCD_SAFETY`` of the first impact, so
no iterate passes a node through another ring's wall. The backtracking line search, the convergence
test (each ring's residual against its own forces) and the contact-set updates are those of
:func:`step.newton.newton_iterate`, for all rings at once.
"""

import math

from ..base.jit import copy_into, kernel
from ..base.layout import ENERGY_TOTAL
from ..base.linalg import lu_factor, lu_solve, solve_band_low_rank_columns
from ..effects.assembly import ring_jacobian
from ..ground.contact import (
    PENETRATION_TOLERANCE,
    activate_penetrating,
    constrain_jacobian,
    constrain_low_rank_rows,
    rest_on_grounds,
)
from ..model import CONTACT_MASS_MODIFICATION, CONTACT_NONE
from ..walls.ring_barrier import (
    add_ring_blocks,
    closest_ratio,
    contact_energy,
    contact_force,
    coupling_entries,
    find_ring_pairs,
    impact_fraction,
    number_coupled_nodes,
    pair_hessians,
)
from ..walls.self_barrier import CCD_SAFETY, find_pairs, reach
from .integrator import coefficients, kinematics, predict
from .newton import (
    FAILED,
    MAX_CONTACT_SET_CHANGES,
    MIN_NEWTON_FRACTION,
    PLAIN,
    SAFE,
    add_barrier_jacobian,
    add_limit_jacobian,
    barrier_filter,
    barrier_start,
    constrain_barrier_rows,
    limit_filter,
    residual,
    update_contact_set,
)


@kernel
def own_pairs(model, r, x, bw):
    """Ring ``r``'s self-contact barrier in safe mode, on its candidate pairs at ``x`` (m) (the
    barrier's Jacobian and force act on them). False if they do not fit."""
    bw.mode[0] = SAFE
    count = find_pairs(x, x, model.rest_len[r], reach(model, r), bw)
    bw.n_pairs[0] = max(count, 0)
    return count >= 0


@kernel
def cross_cut(model, xe, x1, disp, c_x, rc):
    """Fraction (in [0, 1]) of the motions ``xe -> xe + c_x disp`` (the force evaluation point) and
    ``x1 -> x1 + disp`` (the step's end; (R, N, 2) m each) before a node of one ring first meets an
    edge of another, ``CCD_SAFETY`` of it (1 if none does); -1 if the candidates do not fit."""
    cut = 1.0
    for k in range(2 if c_x != 1.0 else 1):
        xa = xe if k == 0 else x1
        scale = c_x if k == 0 else 1.0
        for r in range(xa.shape[0]):
            for i in range(xa.shape[1]):
                for d in range(2):
                    rc.xn[r, i, d] = xa[r, i, d] + scale * disp[r, i, d]
        count = find_ring_pairs(model, xa, rc.xn, rc)
        if count < 0:
            return -1.0
        first = impact_fraction(xa, rc.xn, rc.pairs, count)
        if first <= 1.0:
            cut = min(cut, CCD_SAFETY * first)
    return cut


@kernel
def joint_predict(model, solver, state, v0, h, ws, rc):
    """Every ring's predictor into ``rc.dx``, each cut before its own wall limits and self-contact
    (:func:`step.newton.barrier_start`), then all by one fraction before a node meets another ring.
    False if candidate pairs do not fit."""
    _, c_x, _, _ = coefficients(solver, h)
    for r in range(state.x.shape[0]):
        predict(solver, v0[r], state.a[r], h, ws.dx)
        ws.barrier.mode[0] = SAFE
        if not barrier_start(model, solver, r, state.x[r], h, ws, ws.barrier):
            return False
        copy_into(rc.dx[r], ws.dx)
    cut = cross_cut(model, state.x, state.x, rc.dx, c_x, rc)
    if cut < 1.0:
        for r in range(state.x.shape[0]):
            for i in range(state.x.shape[1]):
                for d in range(2):
                    rc.dx[r, i, d] *= max(cut, 0.0)
    return cut >= 0.0


@kernel
def joint_residual(model, solver, state, v0, trial, h, ws, rc):
    """Every ring's residual at ``rc.dx`` into ``rc.res`` (its ground reactions into
    ``rc.reaction``, ``rc.friction``, ``rc.tangential``; ``trial.x, v, a`` the iterate's state),
    with the contact force between rings at the step's end ``x1`` (``rc.force``; its pairs stay in
    ``rc.pairs`` for the Jacobian). Returns ``(|r|^2, converged, finite)``: converged when
    each ring's ``|r|_inf <= newton_tol`` times its own force scale."""
    for r in range(state.x.shape[0]):
        copy_into(ws.dx, rc.dx[r])
        kinematics(solver, state.x[r], v0[r], state.a[r], h, trial.x[r], trial.v[r], trial.a[r], ws)
        copy_into(rc.xe[r], ws.xe)
    count = find_ring_pairs(model, trial.x, trial.x, rc)
    if count < 0:
        return math.inf, False, False
    rc.force[:, :, :] = 0.0
    contact_force(model, trial.x, rc.pairs, count, rc.force, rc)
    merit = 0.0
    converged = True
    for r in range(state.x.shape[0]):
        copy_into(ws.dx, rc.dx[r])
        if not own_pairs(model, r, rc.xe[r], ws.barrier):
            return math.inf, False, False
        m, worst, scale, finite = residual(
            model, solver, r, state.x[r], v0[r], state.a[r], h, trial.x[r], trial.v[r], trial.a[r], ws,
            trial.active[r],
        )  # fmt: skip
        if not finite:
            return math.inf, False, False
        merit += m
        converged = converged and worst <= solver.newton_tol * scale
        copy_into(rc.res[r], ws.res)
        copy_into(rc.reaction[r], ws.reaction)
        copy_into(rc.friction[r], ws.friction)
        copy_into(rc.tangential[r], ws.tangential)
    return merit, converged, True


@kernel
def _unit_columns(rc, r, res):
    """``rc.cols``: ring ``r``'s residual ``res`` (2N,) in column 0, then the unit columns
    ``e_{2i+d}`` of its coupled nodes ``i``. Returns the number of columns."""
    first = rc.first[r]
    k = rc.first[r + 1] - first
    cols = rc.cols
    for row in range(res.shape[0]):
        cols[row, 0] = res[row]
        for c in range(k):
            cols[row, 1 + c] = 0.0
    for i in range(rc.slot.shape[1]):
        s = rc.slot[r, i]
        if s >= 0:
            cols[2 * i, 1 + s - first] = 1.0
            cols[2 * i + 1, 2 + s - first] = 1.0
    return 1 + k


@kernel
def ring_columns(model, solver, r, state, v0, trial, h, ws, rc):
    """``A_r^-1 [r_r, E_r]`` of ring ``r`` into ``rc.z[r]``: its Newton matrix at its iterate (its
    effects, wall limits and self-contact barrier, the in-ring blocks of the pairs between rings, its
    grounds' row combinations, also applied to the unit columns). False if singular."""
    c_mass, c_x, c_v, _ = coefficients(solver, h)
    bw = ws.barrier
    active, x1 = trial.active[r], trial.x[r]
    copy_into(ws.dx, rc.dx[r])
    kinematics(solver, state.x[r], v0[r], state.a[r], h, x1, trial.v[r], trial.a[r], ws)
    copy_into(ws.reaction, rc.reaction[r])
    copy_into(ws.tangential, rc.tangential[r])
    if not own_pairs(model, r, ws.xe, bw):
        return False
    rank = ring_jacobian(model, r, ws.xe, ws.ve, c_mass, c_x, c_v, ws)
    add_limit_jacobian(model, r, c_x, ws, bw)
    wide = add_barrier_jacobian(model, r, c_x, ws, rank, bw)
    add_ring_blocks(rc.pairs, rc.n_pairs[0], r, x1.shape[0], ws.band, ws.pos, rc)
    n_cols = _unit_columns(rc, r, rc.res[r])
    if model.contact_method != CONTACT_NONE:
        constrain_jacobian(
            ws.surface, active, x1, ws.ve, ws.reaction, ws.tangential, ws.band, ws.pos, ws.u, rank,
            model.node_mass[r], c_mass, c_v, model.friction_regularization,
        )  # fmt: skip
        if wide > rank:
            constrain_barrier_rows(model, active, x1, ws, rank, wide, bw)
        constrain_low_rank_rows(
            ws.surface, active, x1, ws.ve, rc.cols, 1, n_cols, model.friction_regularization
        )
    u, w = ws.u, ws.w
    if wide > rank:
        for k in range(ws.res.shape[0]):
            for c in range(rank):
                bw.u[k, c] = ws.u[k, c]
                bw.w[k, c] = ws.w[k, c]
        u, w = bw.u, bw.w
    if not solve_band_low_rank_columns(
        ws.band, ws.pos, u, w, wide, rc.cols, n_cols, ws.work, rc.zu, rc.ring_cap, rc.ring_piv, rc.ring_coef
    ):
        return False
    for k in range(ws.res.shape[0]):
        for c in range(n_cols):
            rc.z[r, k, c] = rc.cols[k, c]
    return True


@kernel
def combine(rc, n_rings, n2, n_entries):
    """The joint correction ``x = y - Z (I + W^T Z)^-1 W^T y`` into ``rc.step`` from each ring's
    ``rc.z[r] = [y_r, Z_r]`` and the entries of ``W``. False if the capacitance is singular."""
    k = rc.first[n_rings]
    cap, coef = rc.cap, rc.coef
    for a in range(k):
        coef[a] = 0.0
        for c in range(k):
            cap[a, c] = 1.0 if a == c else 0.0
    for e in range(n_entries):
        a, s, row, val = rc.column[e], rc.ring[e], rc.dof[e], rc.value[e]
        coef[a] += val * rc.z[s, row, 0]
        first = rc.first[s]
        for c in range(rc.first[s + 1] - first):
            cap[a, first + c] += val * rc.z[s, row, 1 + c]
    if k > 0:
        if not lu_factor(cap, k, rc.piv):
            return False
        lu_solve(cap, k, rc.piv, coef)
    for r in range(n_rings):
        first = rc.first[r]
        for row in range(n2):
            s = rc.z[r, row, 0]
            for c in range(rc.first[r + 1] - first):
                s -= rc.z[r, row, 1 + c] * coef[first + c]
            rc.step[r, row] = s
    return True


@kernel
def joint_cut(model, solver, state, trial, h, ws, rc):
    """The fraction of the correction ``-rc.step`` to take: the first impact between rings, and each
    ring's own (self-contact, wall limits), ``CCD_SAFETY`` of the first; -1 if pairs do not fit."""
    _, c_x, _, _ = coefficients(solver, h)
    for r in range(state.x.shape[0]):
        for i in range(state.x.shape[1]):
            for d in range(2):
                rc.delta[r, i, d] = -rc.step[r, 2 * i + d]
    cut = cross_cut(model, rc.xe, trial.x, rc.delta, c_x, rc)
    for r in range(state.x.shape[0]):
        if cut < 0.0:
            return cut
        copy_into(ws.xe, rc.xe[r])
        cut = min(cut, barrier_filter(model, r, c_x, ws, rc.step[r], ws.barrier))
        cut = min(cut, limit_filter(c_x, ws.xe, trial.x[r], rc.step[r], ws.barrier))
    return cut


@kernel
def joint_correction(model, solver, state, v0, trial, h, ws, rc):
    """Solve the joint Newton system at the iterate and apply the (cut) correction to ``rc.dx`` (kept
    in ``rc.delta`` for backtracking). Returns ``(ok, settled)`` as :func:`step.newton.correction`."""
    n_rings, n = state.x.shape[0], state.x.shape[1]
    count = rc.n_pairs[0]
    pair_hessians(model, trial.x, rc.pairs, count, 1.0, rc)
    if number_coupled_nodes(rc) < 0:
        return False, False
    n_entries = coupling_entries(rc.pairs, count, n, rc)
    for r in range(n_rings):
        if not ring_columns(model, solver, r, state, v0, trial, h, ws, rc):
            return False, False
    if not combine(rc, n_rings, 2 * n, n_entries):
        return False, False
    cut = joint_cut(model, solver, state, trial, h, ws, rc)
    if cut < 0.0:
        return False, False
    step = 0.0
    size = 0.0
    for r in range(n_rings):
        for i in range(n):
            for d in range(2):
                c = rc.step[r, 2 * i + d] * cut
                if not math.isfinite(c):
                    return False, False
                rc.delta[r, i, d] = c
                rc.dx[r, i, d] -= c
                step = max(step, abs(rc.step[r, 2 * i + d]))  # before the cut, as newton.correction
                size = max(size, abs(state.x[r, i, d]) + abs(rc.dx[r, i, d]))
    return True, step <= 1e-13 * size


@kernel
def joint_contact_set(model, trial, ws, rc):
    """After convergence, every ring's contact-set update (:func:`step.newton.update_contact_set`);
    with no change, the constrained nodes put at rest on their grounds (``rc.arrival``: the work,
    J). Returns True if a set changed."""
    changed = False
    for r in range(trial.x.shape[0]):
        if update_contact_set(ws.surface, trial.active[r], trial.x[r], rc.reaction[r]):
            changed = True
    if not changed:
        for r in range(trial.x.shape[0]):
            arrival = rest_on_grounds(ws.surface, trial.active[r], trial.x[r], trial.v[r], trial.a[r])
            rc.arrival[r] = model.node_mass[r] * arrival
    return changed


@kernel
def joint_start(model, solver, state, v0, trial, h, ws, rc):
    """The predictor of every ring (:func:`joint_predict`); with mass modification, the nodes it
    puts below a ground constrained. Returns (ok, whether a contact set changed)."""
    if not joint_predict(model, solver, state, v0, h, ws, rc):
        return False, False
    changed = False
    if model.contact_method == CONTACT_MASS_MODIFICATION:
        for r in range(state.x.shape[0]):
            copy_into(ws.dx, rc.dx[r])
            kinematics(solver, state.x[r], v0[r], state.a[r], h, trial.x[r], trial.v[r], trial.a[r], ws)
            if activate_penetrating(ws.surface, trial.active[r], trial.x[r], PENETRATION_TOLERANCE):
                changed = True
    return True, changed


@kernel
def joint_newton(model, solver, state, v0, trial, h, ws, rc):
    """Solve one implicit step of all rings jointly from ``state`` (start velocities ``v0``) into
    ``trial`` (``trial.active``: the contact sets, from the step's start). Returns the number of
    Newton corrections, or ``FAILED``. The iteration is :func:`step.newton.newton_iterate`'s for the
    joint unknowns (see the module docstring)."""
    contact = model.contact_method != CONTACT_NONE
    inner_updates = model.contact_method == CONTACT_MASS_MODIFICATION
    ok, changed = joint_start(model, solver, state, v0, trial, h, ws, rc)
    if not ok:
        return FAILED
    set_changes = 1 if changed else 0
    total = 0
    settled = False
    it = 0
    merit_before = math.inf
    lam = 1.0
    while True:
        merit, converged, finite = joint_residual(model, solver, state, v0, trial, h, ws, rc)
        if not finite and (lam <= MIN_NEWTON_FRACTION or merit_before == math.inf):
            return FAILED
        worse = merit > (1.0 - 2e-4 * lam) * merit_before
        if (not finite or not settled) and worse and lam > MIN_NEWTON_FRACTION:
            lam *= 0.5
            for r in range(state.x.shape[0]):
                for i in range(state.x.shape[1]):
                    for d in range(2):
                        rc.dx[r, i, d] += lam * rc.delta[r, i, d]
            continue
        if settled or converged:
            if not contact or not joint_contact_set(model, trial, ws, rc):
                return total
            set_changes += 1
            if set_changes > MAX_CONTACT_SET_CHANGES:
                return FAILED
            settled = False
            it = 0
            merit_before = math.inf
            if not inner_updates and not joint_start(model, solver, state, v0, trial, h, ws, rc)[0]:
                return FAILED
            continue
        if it >= solver.newton_max_iter:
            return FAILED
        ok, settled = joint_correction(model, solver, state, v0, trial, h, ws, rc)
        if not ok:
            return FAILED
        total += 1
        it += 1
        merit_before = merit
        lam = 1.0


@kernel
def contact_transfers(model, x0, x1, before, after, kicks, rc):
    """``rc.transfer[r]`` (J): the energy the contact between rings gave ring ``r`` in a step from
    ``x0`` to ``x1`` (R, N, 2) m, credited to its energy budget. ``before``, ``after``: the rings'
    energy rows (``base.layout.ENERGY``) at both ends. The rings in contact (nonzero work
    ``W_r = sum_i f_i . (x1_i - x0_i)`` of the contact force ``f``, ``rc.force``; ``|W_r|`` into
    ``rc.work``) are credited their energy change ``dE_r`` less their share ``|W_r| / sum |W|`` of
    the change of the whole, ``G = sum_r dE_r + dE_c`` (``E_c``: the contact energy): the credits
    sum to ``-dE_c`` exactly, so energy moves between rings, the budgets together gain what the
    contact energy gave up and no more, and a gain ``G > 0`` of the whole stays above the budgets
    (where the energy test finds it). Rings out of contact get nothing. Returns ``G`` (J; NaN if
    the candidate pairs do not fit). ``kicks`` (R,) J: what each ring's own collision impulses at
    the step's start gave it (:func:`step.stepper.collision_kicks`, credited to its budget on their
    own), left out of its ``dE_r`` (counted here too, a self-contact impulse's loss in one ring was
    shared out by contact work, and credited to that ring twice)."""
    count = find_ring_pairs(model, x0, x1, rc)
    if count < 0:
        return math.nan
    gain = contact_energy(model, x1, rc.pairs, count) - contact_energy(model, x0, rc.pairs, count)
    size = 0.0
    for r in range(x0.shape[0]):
        w = 0.0
        for i in range(x0.shape[1]):
            for d in range(2):
                w += rc.force[r, i, d] * (x1[r, i, d] - x0[r, i, d])
        rc.work[r] = abs(w)
        size += abs(w)
        if w != 0.0:
            gain += after[r, ENERGY_TOTAL] - before[r, ENERGY_TOTAL] - kicks[r]
    for r in range(x0.shape[0]):
        changed = after[r, ENERGY_TOTAL] - before[r, ENERGY_TOTAL] - kicks[r]
        rc.transfer[r] = changed - rc.work[r] / size * gain if rc.work[r] > 0.0 else 0.0
    return gain


@kernel
def pay_from_relative_motion(model, v, rc, excess):
    """Remove ``excess`` (J) of kinetic energy from the motion of the rings in contact
    (``rc.work > 0``) relative to their common centre of mass: each such ring's centre-of-mass
    velocity ``V_r`` becomes ``V + s (V_r - V)`` (all its nodes shifted alike), ``s = sqrt(1 -
    excess / K_rel)``, ``K_rel = sum_r M_r |V_r - V|^2 / 2``; momentum is kept. False (``v``
    untouched) if ``K_rel <= excess``. Generalized-alpha's velocity update lags a contact force
    that switches on within a step (the carried acceleration holds none of it), so the rings lose
    less kinetic energy than the contact energy gains: this takes it back from the approach."""
    n = v.shape[1]
    mass = 0.0
    px = py = 0.0
    for r in range(v.shape[0]):
        if rc.work[r] > 0.0:
            vx, vy = _mean_velocity(v, r)
            m = n * model.node_mass[r]
            mass += m
            px += m * vx
            py += m * vy
    if not mass > 0.0:
        return False
    cx, cy = px / mass, py / mass
    relative = 0.0
    for r in range(v.shape[0]):
        if rc.work[r] > 0.0:
            vx, vy = _mean_velocity(v, r)
            relative += 0.5 * n * model.node_mass[r] * ((vx - cx) ** 2 + (vy - cy) ** 2)
    if not relative > excess:
        return False
    keep = math.sqrt(1.0 - excess / relative)
    for r in range(v.shape[0]):
        if rc.work[r] > 0.0:
            vx, vy = _mean_velocity(v, r)
            for i in range(n):
                v[r, i, 0] += (keep - 1.0) * (vx - cx)
                v[r, i, 1] += (keep - 1.0) * (vy - cy)
    return True


@kernel(inline="always")
def _mean_velocity(v, r):
    """Ring ``r``'s centre-of-mass velocity (m/s; equal node masses)."""
    vx = vy = 0.0
    for i in range(v.shape[1]):
        vx += v[r, i, 0]
        vy += v[r, i, 1]
    return vx / v.shape[1], vy / v.shape[1]


@kernel
def rings_touch(model, x, rc):
    """At the start of a step: whether a node of one ring is within ``dhat`` of another ring's edge
    at ``x`` (the step is then solved jointly); False without ``rc`` (rings that do not collide
    through the barrier). Sets ``rc.mode`` to one by one."""
    if rc is None:
        return False
    rc.mode[0] = PLAIN
    return closest_ratio(model, x, rc) < 1.0


@kernel
def rings_met(model, x0, x1, rc):
    """After a step solved ring by ring from ``x0`` to ``x1``: whether, over the straight motion, a
    node of one ring met another ring's edge (continuous detection) or ended within ``dhat`` of it
    (the step is then solved again jointly); False without ``rc``."""
    if rc is None:
        return False
    count = find_ring_pairs(model, x0, x1, rc)
    if count == 0:
        return False
    if count < 0 or impact_fraction(x0, x1, rc.pairs, count) <= 1.0:
        return True
    return closest_ratio(model, x1, rc) < 1.0
