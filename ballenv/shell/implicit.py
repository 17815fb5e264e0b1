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
solution. Newton's method starts from the predictor ``x0 + h v0 + h^2 a0 / 2`` (cut short of the
grounds), solves with stepsolve.py, cuts each correction so that no vertex reaches a ground
(ground.max_step) and halves it until ``Phi`` drops (Armijo) or, below ``Phi``'s rounding,
``|grad Phi|`` does. It stops when every vertex's residual ``|grad Phi|_i / m_i`` is below
``tol (|g| + R / h^2)`` (m/s^2); otherwise :class:`StepFailure` (the step is rejected).
"""

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ..physics.step import integrator
from . import damping, envelope, friction, ground, potential, stepsolve
from .equilibrium import ARMIJO, HALVINGS, Problem
from .model import ShellModel, build_workspace

F64 = NDArray[np.float64]
FRICTION_LAGS = 3  # updates of the lagged normal forces within a step
LAG_TOL = 1e-3  # their change (relative to the weight) that asks for another


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


class ShellStep(NamedTuple):
    """What the steps of one shell read (SI units)."""

    problem: Problem  # loads: gravity m_i g (N)
    gravity: float  # |g| m/s^2
    normals: F64  # (G, 3) grounds' unit normals
    heights: F64  # (G,) m
    mu: F64  # (G,) friction coefficients
    dhat: float  # m
    kappa: float  # N/m
    slip_speed: float  # eps_v m/s
    damping: float  # c 1/s
    owners: tuple[NDArray[np.int64], NDArray[np.int64]]  # stepsolve.block_owners
    radius: float  # m


def make_step(
    model: ShellModel,
    gravity: F64,
    grounds: tuple[F64, F64, F64],
    contact: tuple[float, float, float],
    c: float,
) -> ShellStep:
    """The step data of ``model`` under ``gravity`` (3,) m/s^2, ``grounds`` (normals, heights, mu),
    ``contact`` (dhat m, kappa N/m, eps_v m/s) and damping ``c`` (1/s)."""
    loads = model.mass[:, None] * gravity[None, :]
    env = envelope.build_envelope(len(model.rest), model.triangles, model.hinges)
    free = np.ones(model.rest.shape, dtype=np.bool_)
    problem = Problem(model, build_workspace(model), env, loads, free)
    owners = stepsolve.block_owners(model.triangles, len(model.rest))
    radius = float(np.linalg.norm(model.rest, axis=1).max())
    return ShellStep(problem, float(np.linalg.norm(gravity)), *grounds, *contact, c, owners, radius)


class Start(NamedTuple):
    """A step's data fixed at its start."""

    x0: F64
    v0: F64
    a0: F64  # zero for backward Euler
    h: float
    target: F64  # y (m)
    coeffs: tuple[float, float, float]  # c_M 1/s^2, c_x, c_v 1/s
    lam: F64  # (V, G) N, lagged normal forces
    basis: F64  # (6, V, 3) damping's W at x0, or (0, V, 3)


def start(method: Integrator, st: ShellStep, x0: F64, v0: F64, a0: F64, h: float) -> Start:
    """The step's fixed data (module doc)."""
    s = method.solver
    c_m, c_x, c_v, am = integrator.coefficients(s, h)
    a = a0 if method.generalized_alpha else np.zeros_like(a0)
    shift = (0.5 - s.beta) - (am * s.beta / (1.0 - am) if method.generalized_alpha else 0.0)
    target = x0 + h * v0 + h * h * shift * a
    lam = np.zeros((len(x0), len(st.heights)))
    ground.normal_forces(x0, st.normals, st.heights, st.dhat, st.kappa, lam)
    mass = st.problem.model.mass
    basis = damping.rigid_basis(x0, mass) if st.damping > 0.0 else np.zeros((0, len(x0), 3))
    return Start(x0, v0, a, h, target, (c_m, c_x, c_v), lam, basis)


def kinematics(method: Integrator, sp: Start, x1: F64) -> tuple[F64, F64, F64]:
    """``(a1, v1, v_a)`` of the end positions ``x1`` (module doc)."""
    s, h = method.solver, sp.h
    a1 = (x1 - sp.x0 - h * sp.v0) / (s.beta * h * h) - (0.5 - s.beta) / s.beta * sp.a0
    v1 = sp.v0 + h * ((1.0 - s.gamma) * sp.a0 + s.gamma * a1)
    return a1, v1, (1.0 - s.alpha_f) * v1 + s.alpha_f * sp.v0


def incremental(method: Integrator, st: ShellStep, sp: Start, x1: F64) -> float:
    """Phi(x1) (J)."""
    p, (c_m, c_x, c_v) = st.problem, sp.coeffs
    m = p.model.mass[:, None]
    total = 0.5 * c_m * float(np.sum(m * (x1 - sp.target) ** 2))
    total += ground.barrier_energy(x1, st.normals, st.heights, st.dhat, st.kappa)
    if not np.isfinite(total):
        return float(total)
    total += potential.energy(p.model, p.ws, sp.x0 + c_x * (x1 - sp.x0), p.loads) / c_x
    e = st.slip_speed * sp.h
    total += friction.friction_energy(x1, sp.x0, st.normals, sp.lam, st.mu, e, np.zeros(3))
    if st.damping > 0.0:
        va = kinematics(method, sp, x1)[2]
        total += (
            st.damping
            / (2.0 * c_v)
            * float(np.sum(va * damping.deformation_rate(va, p.model.mass, sp.basis)))
        )
    return total


def contact_gradient(st: ShellStep, sp: Start, x1: F64, grad: F64, blocks: F64) -> None:
    """Adds the barriers' and friction's gradient (N) and Hessian blocks (N/m) at ``x1``."""
    ground.add_barrier(x1, st.normals, st.heights, st.dhat, st.kappa, grad, blocks)
    e = st.slip_speed * sp.h
    friction.add_friction(x1, sp.x0, st.normals, sp.lam, st.mu, e, grad, blocks, np.zeros(3))


def incremental_gradient(method: Integrator, st: ShellStep, sp: Start, x1: F64) -> tuple[F64, F64]:
    """``(grad Phi (N), the contact's Hessian blocks (V, 3, 3) N/m)`` at ``x1``."""
    p, (c_m, c_x, _) = st.problem, sp.coeffs
    grad = np.zeros_like(x1)
    potential.gradient(p.model, p.ws, sp.x0 + c_x * (x1 - sp.x0), p.loads, grad)
    grad += c_m * p.model.mass[:, None] * (x1 - sp.target)
    if st.damping > 0.0:
        grad += st.damping * damping.deformation_rate(kinematics(method, sp, x1)[2], p.model.mass, sp.basis)
    blocks = np.zeros((len(x1), 3, 3))
    contact_gradient(st, sp, x1, grad, blocks)
    return grad, blocks


def direction(st: ShellStep, sp: Start, x1: F64, grad: F64, blocks: F64, work: F64) -> tuple[F64, int]:
    """Newton's correction (m) and the CG iterations (-1: the envelope solved it)."""
    p, (c_m, c_x, c_v) = st.problem, sp.coeffs
    ws = p.ws
    s = c_x * potential.hessian(p.model, ws, sp.x0 + c_x * (x1 - sp.x0))
    ws.tri_hess[:] *= c_x
    ws.hinge_hess[:] *= c_x
    stepsolve.fold_blocks(ws.tri_hess, st.owners[0], st.owners[1], blocks)
    diagonal = np.repeat(((c_m + st.damping * c_v) * p.model.mass)[:, None], 3, axis=1)
    return stepsolve.solve(p, s, diagonal, st.damping * c_v, sp.basis, -grad, work)


def search(method: Integrator, st: ShellStep, sp: Start, x: F64, dx: F64, grad: F64) -> F64:
    """``x + alpha dx`` for the first accepted ``alpha`` (module doc)."""
    e0 = incremental(method, st, sp, x)
    slope = abs(float(np.sum(grad * dx)))
    rounding = 1e-13 * (st.problem.model.absolute_pressure * st.problem.model.rest_volume + abs(e0))
    g0 = np.abs(grad).max()
    alpha = ground.max_step(x, dx, st.normals, st.heights)
    for _ in range(HALVINGS):
        trial = x + alpha * dx
        e = incremental(method, st, sp, trial)
        if e <= e0 - ARMIJO * alpha * slope:
            return trial
        if abs(e - e0) <= rounding and np.abs(incremental_gradient(method, st, sp, trial)[0]).max() < g0:
            return trial
        alpha *= 0.5
    raise StepFailure(f"the step's line search found no descent (|grad| = {g0:.3e} N)")


class StepResult(NamedTuple):
    """An accepted shell step: end state, its contact force (N) and the work it took."""

    x: F64
    v: F64
    a: F64
    contact_force: F64  # (V, 3) N: the barriers' and friction's force at x1
    iterations: int
    cg_iterations: int
    envelope_solves: int


def newton(method: Integrator, st: ShellStep, sp: Start, x: F64, work: F64) -> tuple[F64, int, int, int]:
    """Newton's iteration from ``x``: ``(x1, iterations, CG iterations, envelope solves)``."""
    goal = method.solver.newton_tol * (st.gravity + st.radius / (sp.h * sp.h))
    mass = st.problem.model.mass[:, None]
    cg_total = envelope_solves = 0
    for iteration in range(method.solver.newton_max_iter + 1):
        grad, blocks = incremental_gradient(method, st, sp, x)
        if not np.all(np.isfinite(grad)):
            break
        if np.abs(grad / mass).max() <= goal:
            return x, iteration, cg_total, envelope_solves
        if iteration == method.solver.newton_max_iter:
            break
        try:
            dx, cg_iterations = direction(st, sp, x, grad, blocks, work)
        except np.linalg.LinAlgError as error:
            raise StepFailure(str(error)) from error
        cg_total += max(cg_iterations, 0)
        envelope_solves += cg_iterations < 0
        x = search(method, st, sp, x, dx, grad)
    raise StepFailure(f"no step after {method.solver.newton_max_iter} Newton iterations")


def step(method: Integrator, st: ShellStep, x0: F64, v0: F64, a0: F64, h: float) -> StepResult:
    """One step of ``h`` (s) from ``(x0, v0, a0)`` (module doc); :class:`StepFailure` if none.

    With friction, the normal forces are lagged as Incremental Potential Contact does: taken at
    ``x0``, then, up to ``FRICTION_LAGS`` times, at the solution, solving again while some normal
    force changed by more than ``LAG_TOL`` of the shell's weight."""
    sp = start(method, st, x0, v0, a0, h)
    guess = x0 + h * v0 + 0.5 * h * h * sp.a0
    x = x0 + ground.max_step(x0, guess - x0, st.normals, st.heights) * (guess - x0)
    work = np.zeros((4, len(x0), 3))
    totals = np.zeros(3, dtype=np.int64)
    weight = float(st.problem.model.mass.sum()) * max(st.gravity, 1.0)
    for lag in range(FRICTION_LAGS + 1):
        x, *counts = newton(method, st, sp, x, work)
        totals += counts
        if not np.any(st.mu > 0.0) or lag == FRICTION_LAGS:
            break
        lam = np.zeros_like(sp.lam)
        ground.normal_forces(x, st.normals, st.heights, st.dhat, st.kappa, lam)
        if np.abs(lam - sp.lam).max() <= LAG_TOL * weight:
            break
        sp = sp._replace(lam=lam)
    force = np.zeros_like(x)
    contact_gradient(st, sp, x, force, np.zeros((len(x), 3, 3)))
    a1, v1, _ = kinematics(method, sp, x)
    return StepResult(x, v1, a1, -force, int(totals[0]), int(totals[1]), int(totals[2]))


def initial_acceleration(st: ShellStep, x: F64, v: F64) -> F64:
    """``a = -M^-1 (grad (Pi + B)(x) + c (M - W W^T) v)`` (m/s^2): generalized-alpha's start."""
    p = st.problem
    grad = np.zeros_like(x)
    potential.gradient(p.model, p.ws, x, p.loads, grad)
    ground.add_barrier(x, st.normals, st.heights, st.dhat, st.kappa, grad, np.zeros((len(x), 3, 3)))
    if st.damping > 0.0:
        grad += st.damping * damping.deformation_rate(v, p.model.mass, damping.rigid_basis(x, p.model.mass))
    return -grad / p.model.mass[:, None]


def total_energy(st: ShellStep, x: F64, v: F64) -> float:
    """Kinetic + stretching + bending + gas + gravity + barrier energy (J)."""
    p = st.problem
    kinetic = 0.5 * float(np.sum(p.model.mass[:, None] * v * v))
    barrier = ground.barrier_energy(x, st.normals, st.heights, st.dhat, st.kappa)
    return kinetic + potential.energy(p.model, p.ws, x, p.loads) + barrier
