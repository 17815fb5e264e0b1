"""One implicit step of a group of shells that may touch: one Newton iteration over all their vertices,
minimising the sum of their incremental potentials and the contact barrier between them (and within
each, with self-contact)::

    Phi(x1) = sum_k Phi_k(x1_k) + B_c(x1)                                                   (J)

``Phi_k`` each shell's incremental potential (increment.py: inertia, skin, gas, gravity, grounds,
friction, damping; the gas's rank-one and the damping's rank-6 terms stay per shell) and ``B_c`` the
point-triangle and edge-edge barrier of contact.py at the step's end, like the grounds'. Newton's
matrix is each shell's plus the touching pairs' projected barrier Hessians, solved by the joint CG
(jointcg.py; no envelope fallback: a CG that does not converge rejects the step). Each Newton
correction, and the predictor, is a straight motion: the broad phase (broadphase.py) lists the pairs
that may come within ``dhat`` along it, and its step is cut so that no vertex reaches a ground
(ground.max_step) nor a triangle (contact.max_step), then halved until ``Phi`` drops (Armijo), as
implicit.py's. The step converges when every shell's residual passes implicit.py's test; friction's
normal forces are lagged as there. The contact between shells is frictionless.
"""

import math
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

from ...physics.base.jit import copy_into, kernel
from ..rest.equilibrium import ARMIJO, HALVINGS
from ..solve import jointcg, stepsolve
from ..touch import broadphase, contact, drums, ground
from . import implicit, increment
from .jointdata import Joint
from .stepdata import ShellStep

F64 = NDArray[np.float64]
R = TypeVar("R")
SHARED_GROUP = 2  # the shortest tuple of shells the compiled step takes (padded)
FAILURES = dict(implicit.FAILURES)
FAILURES[5] = "more contact pairs than their records hold"
FAILURES[6] = "a joint CG that did not converge"


class PairsOverflow(implicit.StepFailure):
    """The contact pairs did not fit their records (they are enlarged and the step retried)."""


@kernel(inline="always")
def flat(a):
    """``a`` (S, V, ...) seen as (S V, ...)."""
    return a.reshape((a.shape[0] * a.shape[1],) + a.shape[2:])


@kernel
def energy(method, sts, jt, x):
    """Phi(x) (J) of the module doc, inf where a vertex reaches a ground or a triangle."""
    total = 0.0
    for k in range(jt.x.shape[0]):
        total += increment.incremental(method, sts[k], sts[k].start, x[k], sts[k].work)
    if not math.isfinite(total):
        return total
    cd = jt.candidates
    return total + contact.energy(cd.pairs, cd.n_pairs[0], flat(x), jt.rest, jt.kappa, jt.dhat, jt.scratch)


@kernel
def gradient(method, sts, jt, x, grad, blocks, hessian):
    """``grad Phi`` (N) and the vertex blocks (N/m) at ``x``; with ``hessian`` the touching pairs'
    matrices into ``jt``. Returns the touching pairs, -1 if they do not fit."""
    for k in range(jt.x.shape[0]):
        st = sts[k]
        increment.incremental_gradient(method, st, st.start, x[k], st.work, grad[k], blocks[k])
    cd = jt.candidates
    pairs, count = cd.pairs, cd.n_pairs[0]
    n = contact.add_barrier(
        pairs,
        count,
        flat(x),
        jt.rest,
        jt.kappa,
        jt.dhat,
        flat(grad),
        flat(blocks),
        jt.active,
        jt.hess,
        jt.scratch,
        hessian,
    )
    if hessian:
        jt.n_active[0] = max(n, 0)
    return n


@kernel
def max_step(sts, jt, x, dx):
    """The candidates of the motion ``x + alpha dx`` (broadphase.py) and the largest ``alpha <= 1``
    that keeps every vertex off the grounds and the triangles; -1 if the candidates do not fit."""
    cd = jt.candidates
    if broadphase.find_pairs(cd, flat(x), flat(dx), jt.dhat, jt.box) < 0:
        return -1.0
    alpha = 1.0
    for k in range(jt.x.shape[0]):
        alpha = min(alpha, ground.max_step(x[k], dx[k], sts[k].normals, sts[k].heights))
        alpha = min(alpha, drums.max_step(sts[k].drums, x[k], dx[k]))
    return contact.max_step(cd.pairs, cd.n_pairs[0], flat(x), flat(dx), alpha, jt.scratch)


@kernel
def _rounding(sts, jt, e0):
    out = 1e-13 * abs(e0)
    for k in range(jt.x.shape[0]):
        model = sts[k].problem.model
        out += 1e-13 * model.absolute_pressure[0] * model.rest_volume
    return out


@kernel
def search(method, sts, jt, e0, alpha):
    """Moves ``jt.x`` to ``x + a jt.dx`` for the first accepted ``a`` of ``alpha, alpha / 2, ...``
    (implicit.search's rule); returns Phi there (J), or NaN if none was accepted."""
    x, dx, trial = jt.x, jt.dx, jt.trial
    slope = g0 = 0.0
    for k in range(x.shape[0]):
        for i in range(x.shape[1]):
            for c in range(3):
                slope += jt.grad[k, i, c] * dx[k, i, c]
                g0 = max(g0, abs(jt.grad[k, i, c]))
    slope = abs(slope)
    rounding = _rounding(sts, jt, e0)
    for _ in range(HALVINGS):
        for k in range(x.shape[0]):
            for i in range(x.shape[1]):
                for c in range(3):
                    trial[k, i, c] = x[k, i, c] + alpha * dx[k, i, c]
        e = energy(method, sts, jt, trial)
        accept = e <= e0 - ARMIJO * alpha * slope
        if not accept and abs(e - e0) <= rounding:
            gradient(method, sts, jt, trial, jt.trial_grad, jt.trial_blocks, False)
            accept = implicit.largest(flat(jt.trial_grad)) < g0
        if accept:
            copy_into(x, trial)
            return e
        alpha *= 0.5
    return math.nan


@kernel
def _residual(method, sts, jt):
    """The largest ratio over the shells of the residual to its goal (implicit.newton), NaN if a
    gradient is not finite; and the force (N) the goals ask for, the smallest."""
    h = sts[0].start.coef[0]
    worst, force_goal = 0.0, math.inf
    for k in range(jt.x.shape[0]):
        st = sts[k]
        mass = st.problem.model.mass
        goal = method.solver.newton_tol * (st.gravity + st.radius / (h * h))
        r = implicit.residual_acceleration(jt.grad[k], mass)
        if math.isnan(r):
            return math.nan, force_goal
        worst = max(worst, r / goal)
        for i in range(mass.shape[0]):
            force_goal = min(force_goal, goal * mass[i])
    return worst, force_goal


@kernel
def direction(sts, jt, fresh, rtol):
    """Newton's correction (m) into ``jt.dx`` (jointcg.py); the CG iterations, -1 if it failed."""
    for k in range(jt.x.shape[0]):
        st = sts[k]
        sp, wk = st.start, st.work
        c_x, s = increment.newton_matrix(st, sp, jt.x[k], wk, fresh)
        coefficients = (c_x, s, st.damping * sp.coef[3], rtol)
        stepsolve.load(st.problem, st.op, coefficients, jt.blocks[k], wk.mass_term, sp.basis, fresh)
        for i in range(jt.x.shape[1]):
            for c in range(3):
                jt.rhs[k, i, c] = -jt.grad[k, i, c]
    return jointcg.pcg(sts, jt, jt.rhs, jt.dx, rtol, stepsolve.CG_MAX_ITER)


@kernel
def newton(method, sts, jt):
    """Newton's iteration from ``jt.x``: ``(status, iterations, CG iterations)`` (status 0:
    converged, else a key of ``FAILURES``)."""
    cg_total = 0
    previous = math.inf
    e = energy(method, sts, jt, jt.x)
    for iteration in range(method.solver.newton_max_iter + 1):
        if gradient(method, sts, jt, jt.x, jt.grad, jt.blocks, True) < 0:
            return 5, iteration, cg_total
        ratio, force_goal = _residual(method, sts, jt)
        if math.isnan(ratio):
            return 1, iteration, cg_total
        if ratio <= 1.0:
            return 0, iteration, cg_total
        if iteration == method.solver.newton_max_iter:
            break
        fresh = iteration == 0 or ratio > implicit.LAG_CONTRACTION * previous
        previous = ratio
        iterations = direction(sts, jt, fresh, implicit.forcing(flat(jt.grad), force_goal))
        if iterations < 0:
            return 6, iteration, cg_total
        cg_total += iterations
        alpha = max_step(sts, jt, jt.x, jt.dx)
        if alpha < 0.0:
            return 5, iteration, cg_total
        e = search(method, sts, jt, e, alpha)
        if math.isnan(e):
            return 4, iteration, cg_total
    return 2, method.solver.newton_max_iter, cg_total


@kernel
def _start(method, sts, jt, x0, v0, a0, h):
    """Each shell's start (increment.begin) and the predictor, cut short of grounds and triangles,
    into ``jt.x``; False if the candidate pairs did not fit."""
    for k in range(jt.x.shape[0]):
        st = sts[k]
        increment.begin(method, st, x0[k], v0[k], a0[k], h, st.start)
        for i in range(x0.shape[1]):
            for c in range(3):
                jt.dx[k, i, c] = h * v0[k, i, c] + 0.5 * h * h * st.start.a0[i, c]
    alpha = max_step(sts, jt, x0, jt.dx)
    for k in range(x0.shape[0]):
        for i in range(x0.shape[1]):
            for c in range(3):
                jt.x[k, i, c] = x0[k, i, c] + alpha * jt.dx[k, i, c]
    return alpha >= 0.0


@kernel
def _lags_changed(sts, jt):
    """Friction's normal forces at ``jt.x``: True (and taken as the lagged ones) if one of a shell
    changed by more than implicit.LAG_TOL of its weight."""
    changed = False
    for k in range(jt.x.shape[0]):
        st = sts[k]
        copy_into(st.work.x, jt.x[k])
        weight = st.problem.model.mass.sum() * max(st.gravity, 1.0)
        changed |= implicit.lag_changed(st, st.start, st.work, weight)
    if changed:
        for k in range(jt.x.shape[0]):
            copy_into(sts[k].start.lam, sts[k].work.lam)
            drums.accept_lag(sts[k].drums)
    return changed


@kernel
def _finish(method, sts, jt):
    """The contact force (grounds, friction and pairs, N) and each shell's ``v1``, ``a1`` at
    ``jt.x``."""
    jt.force[:] = 0.0
    jt.trial_blocks[:] = 0.0
    for k in range(jt.x.shape[0]):
        st = sts[k]
        increment.contact_gradient(st, st.start, jt.x[k], jt.force[k], jt.trial_blocks[k], st.work.u3)
    gradient_pairs(jt, jt.x, jt.force, jt.trial_blocks)
    for k in range(jt.x.shape[0]):
        st = sts[k]
        for i in range(jt.x.shape[1]):
            for c in range(3):
                jt.force[k, i, c] = -jt.force[k, i, c]
        increment.kinematics(method, st.start, jt.x[k], st.work.a1, st.work.v1, st.work.va)


@kernel
def gradient_pairs(jt, x, grad, blocks):
    """Adds the pairs' barrier gradient (N) at ``x`` to ``grad`` (S, V, 3)."""
    cd = jt.candidates
    contact.add_barrier(
        cd.pairs, cd.n_pairs[0], flat(x), jt.rest, jt.kappa, jt.dhat, flat(grad), flat(blocks), jt.active,
        jt.hess, jt.scratch, False,
    )  # fmt: skip


def padded(sts: tuple[R, ...]) -> tuple[R, ...]:
    """``sts`` with its first record repeated up to ``SHARED_GROUP`` records. A tuple's length is
    part of its numba type, so the step of one shell with self-contact and that of a pair compile
    once between them; the kernels loop over the group's ``jt.x.shape[0]`` shells, never over the
    tuple's padding."""
    return sts + (sts[0],) * (SHARED_GROUP - len(sts))


@kernel
def step_kernel(method, sts, jt, x0, v0, a0, h):
    """One joint step of ``h`` (s) from ``(x0, v0, a0)`` (S, V, 3) into ``jt.x``, ``jt.force`` and
    each shell's ``work.v1``, ``work.a1`` and ``work.energy`` (J: its own, implicit.end_energy; the
    pairs' barrier energy added to the first shell's): ``(status, Newton iterations, CG
    iterations)``."""
    if not _start(method, sts, jt, x0, v0, a0, h):
        return 5, 0, 0
    frictional = False
    for k in range(jt.x.shape[0]):
        for g in range(sts[k].mu.shape[0]):
            frictional |= sts[k].mu[g] > 0.0
        frictional |= drums.frictional(sts[k].drums)
    newton_total = cg_total = 0
    for lag in range(implicit.FRICTION_LAGS + 1):
        status, iterations, cg_iterations = newton(method, sts, jt)
        newton_total += iterations
        cg_total += cg_iterations
        if status != 0:
            return status, newton_total, cg_total
        if not frictional or lag == implicit.FRICTION_LAGS or not _lags_changed(sts, jt):
            break
    _finish(method, sts, jt)
    for k in range(jt.x.shape[0]):
        sts[k].work.energy[0] = implicit.end_energy(sts[k], jt.x[k], sts[k].work.v1)
    cd = jt.candidates
    sts[0].work.energy[0] += contact.energy(
        cd.pairs, cd.n_pairs[0], flat(jt.x), jt.rest, jt.kappa, jt.dhat, jt.scratch
    )
    return 0, newton_total, cg_total


def step(
    method: implicit.Integrator, sts: tuple[ShellStep, ...], jt: Joint, x0: F64, v0: F64, a0: F64, h: float
) -> list[implicit.StepResult]:
    """One joint step of ``h`` (s) from ``(x0, v0, a0)`` (S, V, 3) (module doc): each shell's
    result, the group's Newton and CG iterations and its pairs' barrier energy counted on its first
    shell; :class:`implicit.StepFailure` (:class:`PairsOverflow`) if none. The records pass to the
    compiled step by reference (``jit.by_reference``: a pointer each, where a NamedTuple passes
    every array), the shells' tuple :func:`padded`."""
    status, iterations, cg_iterations = step_kernel(method, padded(sts), jt, x0, v0, a0, h)
    if status == 5:
        raise PairsOverflow(FAILURES[5])
    if status != 0:
        raise implicit.StepFailure(f"the joint step of {h:.3e} s failed: {FAILURES[status]}")
    out = []
    for k, st in enumerate(sts):
        work = (iterations, cg_iterations, 0) if k == 0 else (0, 0, 0)
        wk = st.work
        ends = (jt.x[k].copy(), wk.v1.copy(), wk.a1.copy(), jt.force[k].copy(), float(wk.energy[0]))
        out.append(implicit.StepResult(*ends, *work))
    return out
