"""One implicit step of a shell: backward Euler or generalized-alpha, as the minimiser of an
incremental potential, by Newton's method on its exact Hessian.

Generalized-alpha (Chung & Hulbert 1993; ``alpha_m``, ``alpha_f``, ``beta``, ``gamma`` and the
coefficients ``c_M = (1 - alpha_m) / (beta h^2)``, ``c_x = 1 - alpha_f``, ``c_v = c_x gamma / (beta h)``
shared with the ring, ``ballenv.physics.step.integrator``) updates, for a step of ``h`` (s) from
``x0`` (m), ``v0`` (m/s), ``a0`` (m/s^2)::

    a1 = (x1 - x0 - h v0) / (beta h^2) - (1/2 - beta) / beta a0,   v1 = v0 + h ((1 - gamma) a0 + gamma a1)
    M ((1 - alpha_m) a1 + alpha_m a0) = -grad Pi(x_a) - grad (B + D)(x1) - c (M - W W^T) v_a

with ``x_a = x0 + c_x (x1 - x0)``, ``v_a = (1 - alpha_f) v1 + alpha_f v0``; ``Pi`` stretching +
bending + gas - gravity's work (potential.py, loads ``m_i g``), ``B`` the grounds' barriers
(ground.py) and ``D`` friction (friction.py), both at the step's end, and the deformation damping
(damping.py). Backward Euler is ``alpha_m = alpha_f = 0``, ``beta = gamma = 1`` with ``a0 = 0``.
That equation is the stationarity of (J)::

    Phi(x1) = c_M / 2 sum_i m_i |x1_i - y_i|^2 + Pi(x_a) / c_x + B(x1) + D(x1)
              + c / (2 c_v) v_a^T (M - W W^T) v_a

``y = x0 + h v0 + h^2 ((1/2 - beta) - alpha_m beta / (1 - alpha_m)) a0``, whose Hessian (N/m)
``c_M M + c_x K(x_a) + Hess (B + D) + c c_v (M - W W^T)`` is symmetric and positive definite near a
solution (increment.py). Newton's method starts from the predictor ``x0 + h v0 + h^2 a0 / 2`` (cut
short of the grounds), solves with stepsolve.py, cuts each correction so that no vertex reaches a
ground (ground.max_step) and halves it until ``Phi`` drops (Armijo) or, below ``Phi``'s rounding,
``|grad Phi|`` does; before each correction after the first, the vertices touching a ground
descend each on its own part of ``Phi`` (relax.py: the barrier and friction's stiff kinks, which
would otherwise cut the whole correction's step), kept if ``Phi`` dropped. It stops when every
vertex's residual ``|grad Phi|_i / m_i`` is below ``tol (|g| + R / h^2)`` (m/s^2); otherwise
:class:`StepFailure` (the step is rejected). The skin's element matrices ``K`` are those of the
step's first iterate, evaluated again only when an iteration lowered the residual by less than
``1 / LAG_CONTRACTION`` (the stopping test, not the matrix, sets the solution); CG's tolerance
follows the force the test asks for (:func:`forcing`). The step is one compiled call
(:func:`step_kernel`) on the preallocated records of stepdata.py.
"""

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ...physics.base.jit import copy_into, kernel
from ...physics.base.record_ref import RecordRef, reference
from ...physics.step import integrator
from ..rest.equilibrium import ARMIJO, HALVINGS
from ..skin import damping, potential
from ..touch import drum, drums, ground
from . import increment, relax
from .stepdata import ShellStep, Start, make_start

F64 = NDArray[np.float64]
FRICTION_LAGS = 3  # updates of the lagged normal forces within a step
LAG_TOL = 1e-3  # their change (relative to the weight) that asks for another
FORCING = 0.25  # a Newton direction's linear residual against the force Newton's test asks for
CG_RTOL_MIN = 1e-8  # its bounds relative to the gradient (stepsolve.py)
CG_RTOL_MAX = 1e-1
LAG_CONTRACTION = 0.1  # a Newton residual above this fraction of the last asks for new element matrices
FAILURES = {
    1: "a non-finite gradient",
    2: "no convergence within newton_max_iter Newton iterations",
    3: "a Newton matrix that is not positive definite",
    4: "a line search that found no descent",
}  # the step kernel's status codes (0: converged)


class StepFailure(RuntimeError):
    """Newton's method found no step (it is rejected and retried shorter)."""


class Integrator(NamedTuple):
    """The method's parameters as the ring's ``integrator.Solver`` record (its coefficient kernels)."""

    solver: integrator.Solver
    generalized_alpha: bool


def make_integrator(name: str, rho_infinity: float, tol: float, max_iter: int, dt: float) -> Integrator:
    """``"backward_euler"`` or ``"generalized_alpha"`` (of spectral radius ``rho_infinity``)."""
    ga = name == "generalized_alpha"
    am, af, b, g = integrator.generalized_alpha_parameters(rho_infinity) if ga else (0.0, 0.0, 1.0, 1.0)
    method = integrator.METHOD_GENERALIZED_ALPHA if ga else integrator.METHOD_BACKWARD_EULER
    solver = integrator.Solver(
        method, am, af, b, g, tol, max_iter, dt, dt, True, integrator.STEP_GROWTH, 0.0, 0.0
    )
    return Integrator(solver, ga)


@kernel
def search(method, st, sp, wk, e0):
    """Moves ``wk.x`` to ``x + alpha wk.dx`` for the first accepted ``alpha`` (module doc); returns
    Phi there (J), or NaN if no ``alpha`` was accepted."""
    x, dx, grad, trial = wk.x, wk.dx, wk.grad, wk.trial
    slope = 0.0
    g0 = 0.0
    for i in range(x.shape[0]):
        for c in range(3):
            slope += grad[i, c] * dx[i, c]
            g0 = max(g0, abs(grad[i, c]))
    slope = abs(slope)
    model = st.problem.model
    rounding = 1e-13 * (model.absolute_pressure[0] * model.rest_volume + abs(e0))
    alpha = min(ground.max_step(x, dx, st.normals, st.heights), drums.max_step(st.drums, x, dx))
    for _ in range(HALVINGS):
        for i in range(x.shape[0]):
            for c in range(3):
                trial[i, c] = x[i, c] + alpha * dx[i, c]
        e = increment.incremental(method, st, sp, trial, wk)
        accept = e <= e0 - ARMIJO * alpha * slope
        if not accept and abs(e - e0) <= rounding:
            increment.incremental_gradient(method, st, sp, trial, wk, wk.trial_grad, wk.trial_blocks)
            accept = largest(wk.trial_grad) < g0
        if accept:
            copy_into(x, trial)
            return e
        alpha *= 0.5
    return math.nan


@kernel
def largest(a):
    """The largest ``|a_ic|``."""
    out = 0.0
    for i in range(a.shape[0]):
        for c in range(3):
            out = max(out, abs(a[i, c]))
    return out


@kernel
def residual_acceleration(grad, mass):
    """The largest ``|grad_ic| / m_i`` (m/s^2), NaN if a component is not finite."""
    worst = 0.0
    for i in range(grad.shape[0]):
        for c in range(3):
            if not math.isfinite(grad[i, c]):
                return math.nan
            worst = max(worst, abs(grad[i, c]) / mass[i])
    return worst


@kernel
def forcing(grad, force_goal):
    """CG's relative tolerance for a Newton direction from the gradient ``grad`` (N): a residual of
    ``FORCING`` times the force ``force_goal`` (N) that Newton's test asks for, within
    ``[CG_RTOL_MIN, CG_RTOL_MAX]``: near convergence the linear residual is what is left of the
    gradient, the rigid motion's part included, which nothing else corrects."""
    norm = 0.0
    for i in range(grad.shape[0]):
        for c in range(3):
            norm += grad[i, c] * grad[i, c]
    return min(CG_RTOL_MAX, max(CG_RTOL_MIN, FORCING * force_goal / math.sqrt(norm)))


@kernel
def relaxed(method, st, sp, wk, goal, e, residual):
    """The contact vertices' own descent (relax.py) from ``wk.x``, where ``Phi`` is ``e`` (J) and
    the residual ``residual`` (m/s^2): kept if ``Phi`` dropped, with the gradient there. Returns
    ``(Phi, residual)`` at ``wk.x``."""
    copy_into(wk.trial, wk.x)
    if relax.relax(st, sp, wk, goal) == 0:
        return e, residual
    moved = increment.incremental(method, st, sp, wk.x, wk)
    if not moved < e:
        copy_into(wk.x, wk.trial)
        return e, residual
    increment.incremental_gradient(method, st, sp, wk.x, wk, wk.grad, wk.blocks)
    return moved, residual_acceleration(wk.grad, st.problem.model.mass)


@kernel
def newton(method, st, sp, wk, matrices):
    """Newton's iteration from ``wk.x``: ``(status, iterations, CG iterations, envelope solves)``
    (status 0: converged, else a key of ``FAILURES``). The skin's element matrices are evaluated
    at its first iterate if ``matrices`` (else those of an earlier Newton iteration of the step are
    kept), and again when an iteration contracted the residual too little."""
    h = sp.coef[0]
    goal = method.solver.newton_tol * (st.gravity + st.radius / (h * h))
    mass = st.problem.model.mass
    cg_total = envelope_solves = 0
    previous = math.inf
    lightest = math.inf
    for i in range(mass.shape[0]):
        lightest = min(lightest, mass[i])
    e = math.nan  # Phi at wk.x, evaluated once a line search needs it
    for iteration in range(method.solver.newton_max_iter + 1):
        increment.incremental_gradient(method, st, sp, wk.x, wk, wk.grad, wk.blocks)
        residual = residual_acceleration(wk.grad, mass)
        if iteration > 0 and residual > goal:
            e, residual = relaxed(method, st, sp, wk, goal, e, residual)
        if math.isnan(residual):
            return 1, iteration, cg_total, envelope_solves
        if residual <= goal:
            return 0, iteration, cg_total, envelope_solves
        if iteration == method.solver.newton_max_iter:
            break
        # the envelope's fallback changes the element matrices: new ones after it
        fresh = (iteration == 0 and matrices) or envelope_solves > 0 or residual > LAG_CONTRACTION * previous
        previous = residual
        rtol = forcing(wk.grad, goal * lightest)
        iterations = increment.direction(st, sp, wk.x, wk.grad, wk.blocks, wk, wk.dx, fresh, rtol)
        if iterations == -2:
            return 3, iteration, cg_total, envelope_solves
        cg_total += max(iterations, 0)
        envelope_solves += iterations == -1
        if iteration == 0:
            e = increment.incremental(method, st, sp, wk.x, wk)
        e = search(method, st, sp, wk, e)
        if math.isnan(e):
            return 4, iteration, cg_total, envelope_solves
    return 2, method.solver.newton_max_iter, cg_total, envelope_solves


@kernel
def lag_changed(st, sp, wk, weight):
    """The normal forces at ``wk.x`` into ``wk.lam``: True if one differs from the lagged ones by
    more than ``LAG_TOL`` of ``weight`` (N)."""
    ground.normal_forces(wk.x, st.normals, st.heights, st.dhat, st.kappa, wk.lam)
    change = 0.0
    for i in range(wk.lam.shape[0]):
        for g in range(wk.lam.shape[1]):
            change = max(change, abs(wk.lam[i, g] - sp.lam[i, g]))
    change = max(change, drums.lag_change(st.drums, wk.x, st.dhat, st.kappa))
    return change > LAG_TOL * weight


@kernel(nogil=True)  # releases Python's lock: envs on threads step in parallel
def step_kernel(method, st, x0, v0, a0, h):
    """One step of ``h`` (s) from ``(x0, v0, a0)`` into ``st.work`` (``x``, ``v1``, ``a1``,
    ``force``): ``(status, Newton iterations, CG iterations, envelope solves)`` (see :func:`step`)."""
    sp, wk = st.start, st.work
    increment.begin(method, st, x0, v0, a0, h, sp)
    for i in range(x0.shape[0]):
        for c in range(3):
            wk.dx[i, c] = h * v0[i, c] + 0.5 * h * h * sp.a0[i, c]
    alpha = min(ground.max_step(x0, wk.dx, st.normals, st.heights), drums.max_step(st.drums, x0, wk.dx))
    for i in range(x0.shape[0]):
        for c in range(3):
            wk.x[i, c] = x0[i, c] + alpha * wk.dx[i, c]
    weight = st.problem.model.mass.sum() * max(st.gravity, 1.0)
    frictional = False
    for g in range(st.mu.shape[0]):
        frictional |= st.mu[g] > 0.0
    frictional |= drums.frictional(st.drums)
    newton_total = cg_total = envelope_total = 0
    for lag in range(FRICTION_LAGS + 1):
        matrices = lag == 0 or envelope_total > 0  # a later round starts from the last iterate's
        status, iterations, cg_iterations, envelope_solves = newton(method, st, sp, wk, matrices)
        newton_total += iterations
        cg_total += cg_iterations
        envelope_total += envelope_solves
        if status != 0:
            return status, newton_total, cg_total, envelope_total
        if not frictional or lag == FRICTION_LAGS or not lag_changed(st, sp, wk, weight):
            break
        copy_into(sp.lam, wk.lam)
        drums.accept_lag(st.drums)
    wk.force[:] = 0.0
    wk.trial_blocks[:] = 0.0
    increment.contact_gradient(st, sp, wk.x, wk.force, wk.trial_blocks, wk.u3)
    for i in range(x0.shape[0]):
        for c in range(3):
            wk.force[i, c] = -wk.force[i, c]
    increment.kinematics(method, sp, wk.x, wk.a1, wk.v1, wk.va)
    wk.energy[0] = end_energy(st, wk.x, wk.v1)
    return 0, newton_total, cg_total, envelope_total


@kernel
def end_energy(st, x, v):
    """Kinetic + stretching + bending + gas + gravity + barrier energy (J) of ``(x, v)``."""
    p = st.problem
    kinetic = 0.0
    for i in range(x.shape[0]):
        for c in range(3):
            kinetic += 0.5 * p.model.mass[i] * v[i, c] * v[i, c]
    barrier = ground.barrier_energy(x, st.normals, st.heights, st.dhat, st.kappa)
    barrier += drums.energy(st.drums, x, st.dhat, st.kappa)
    return kinetic + potential.energy(p.model, p.ws, x, p.loads) + barrier


class StepResult(NamedTuple):
    """An accepted shell step: end state, its contact force (N) and the work it took."""

    x: F64
    v: F64
    a: F64
    contact_force: F64  # (V, 3) N: the barriers' and friction's force at x1
    energy: float  # J: total_energy at the end
    iterations: int
    cg_iterations: int
    envelope_solves: int


def step(method: Integrator, st: ShellStep | RecordRef, x0: F64, v0: F64, a0: F64, h: float) -> StepResult:
    """One step of ``h`` (s) from ``(x0, v0, a0)`` (module doc); :class:`StepFailure` if none.
    ``st`` is passed to the compiled step by reference: a RecordRef of it, or the record itself
    (then :func:`record_ref.reference`'s).

    With friction, the normal forces are lagged as Incremental Potential Contact does: taken at
    ``x0``, then, up to ``FRICTION_LAGS`` times, at the solution, solving again while some normal
    force changed by more than ``LAG_TOL`` of the shell's weight."""
    ref = st if isinstance(st, RecordRef) else reference(st)
    status, iterations, cg_iterations, envelope_solves = step_kernel(method, ref, x0, v0, a0, h)
    if status != 0:
        raise StepFailure(f"the step of {h:.3e} s failed: {FAILURES[status]}")
    wk = ref.record.work
    return StepResult(
        wk.x.copy(), wk.v1.copy(), wk.a1.copy(), wk.force.copy(), float(wk.energy[0]),
        iterations, cg_iterations, envelope_solves,
    )  # fmt: skip


def start(method: Integrator, st: ShellStep, x0: F64, v0: F64, a0: F64, h: float) -> Start:
    """A new ``Start`` of a step of ``h`` (s) from ``(x0, v0, a0)`` (increment.begin)."""
    sp = make_start(len(x0), len(st.heights), st.damping > 0.0)
    increment.begin(method, st, x0, v0, a0, h, sp)
    return sp


def incremental(method: Integrator, st: ShellStep, sp: Start, x1: F64) -> float:
    """Phi(x1) (J) (increment.incremental)."""
    return float(increment.incremental(method, st, sp, np.ascontiguousarray(x1), st.work))


def incremental_gradient(method: Integrator, st: ShellStep, sp: Start, x1: F64) -> tuple[F64, F64]:
    """``(grad Phi (N), the contact's Hessian blocks (V, 3, 3) N/m)`` at ``x1``."""
    grad, blocks = np.zeros_like(x1), np.zeros((len(x1), 3, 3))
    increment.incremental_gradient(method, st, sp, np.ascontiguousarray(x1), st.work, grad, blocks)
    return grad, blocks


def direction(st: ShellStep, sp: Start, x1: F64, grad: F64, blocks: F64) -> tuple[F64, int]:
    """Newton's correction (m) at ``x1``, solved to CG's tightest tolerance (``CG_RTOL_MIN`` of the
    gradient), and the CG iterations (-1: the envelope solved it)."""
    dx = np.zeros_like(x1)
    x1 = np.ascontiguousarray(x1)
    st.work.bending_age[0] = -1
    iterations = increment.direction(st, sp, x1, grad, blocks, st.work, dx, True, CG_RTOL_MIN)
    if iterations == -2:
        raise StepFailure(FAILURES[3])
    return dx, int(iterations)


def initial_acceleration(st: ShellStep, x: F64, v: F64) -> F64:
    """``a = -M^-1 (grad (Pi + B)(x) + c (M - W W^T) v)`` (m/s^2): generalized-alpha's start."""
    p = st.problem
    grad = np.zeros_like(x)
    potential.gradient(p.model, p.ws, x, p.loads, grad)
    ground.add_barrier(x, st.normals, st.heights, st.dhat, st.kappa, grad, np.zeros((len(x), 3, 3)))
    if st.drums is not None:
        drum.add_barrier(x, st.drums, st.dhat, st.kappa, grad, np.zeros((len(x), 3, 3)), True)
    if st.damping > 0.0:
        basis, rate = np.zeros((6, len(x), 3)), np.zeros_like(x)
        damping.rigid_basis(x, p.model.mass, basis)
        damping.deformation_rate(v, p.model.mass, basis, rate)
        grad += st.damping * rate
    return -grad / p.model.mass[:, None]


def total_energy(st: ShellStep, x: F64, v: F64) -> float:
    """Kinetic + stretching + bending + gas + gravity + barrier energy (J)."""
    return float(end_energy(st, np.ascontiguousarray(x), np.ascontiguousarray(v)))
