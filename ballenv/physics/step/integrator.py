"""Time integrators: backward Euler and generalized-alpha, and the step-control settings.

The unknown of a step of size ``h`` (s) is the displacement ``dx = x1 - x0`` (m). Backward Euler::

    v1 = dx / h,   M (v1 - v0) / h = F(x1, v1)

Generalized-alpha (Chung & Hulbert 1993; Newmark update with ``beta``, ``gamma``)::

    a1 = (dx - h v0) / (beta h^2) - (1/2 - beta) / beta a0
    v1 = v0 + h ((1 - gamma) a0 + gamma a1)
    M ((1 - alpha_m) a1 + alpha_m a0) = F((1 - alpha_f) x1 + alpha_f x0, (1 - alpha_f) v1 + alpha_f v0)

Backward Euler is the special case ``alpha_m = alpha_f = 0``, ``beta = gamma = 1`` of the residual
``M ((1 - alpha_m) a1 + alpha_m a0) - F`` with ``a1 = (dx - h v0) / h^2``. Each integrator provides
its coefficients (:func:`coefficients`), predictor (:func:`predict`), update (:func:`kinematics`)
and the reaction of a node stopped by a ground per unit of its momentum (:func:`arrival_factor`),
which the step-size control nets out. Nothing outside this module branches on the method.
"""

from typing import NamedTuple

from ..base.jit import kernel

METHOD_BACKWARD_EULER = 0
METHOD_GENERALIZED_ALPHA = 1
STEP_GROWTH = 1.25  # largest growth of an accepted adaptive step


class Solver(NamedTuple):
    method: int
    alpha_m: float
    alpha_f: float
    beta: float
    gamma: float
    newton_tol: float  # residual relative to the forces it balances
    newton_max_iter: int
    dt: float  # s
    dt_min: float  # s
    adaptive: bool
    growth: float
    rtol: float  # local error tolerance relative to the ring's radius; 0: no error control
    atol: float  # m: absolute local error tolerance on positions


def generalized_alpha_parameters(rho_infinity):
    """Chung-Hulbert parameters ``(alpha_m, alpha_f, beta, gamma)`` for a spectral radius rho_inf.

    ``alpha_m = (2 rho - 1) / (rho + 1)``, ``alpha_f = rho / (rho + 1)``,
    ``gamma = 1/2 - alpha_m + alpha_f``, ``beta = (1 - alpha_m + alpha_f)^2 / 4``: second order,
    unconditionally stable, high-frequency damping set by ``rho`` (1: none).
    """
    r = float(rho_infinity)
    alpha_m = (2.0 * r - 1.0) / (r + 1.0)
    alpha_f = r / (r + 1.0)
    gamma = 0.5 - alpha_m + alpha_f
    beta = 0.25 * (1.0 - alpha_m + alpha_f) ** 2
    return alpha_m, alpha_f, beta, gamma


def build_solver(scene):
    """Integrator coefficients and step control of ``scene``."""
    if scene.integrator == "backward_euler":
        method = METHOD_BACKWARD_EULER
        alpha_m = alpha_f = 0.0
        beta = gamma = 1.0
    else:
        method = METHOD_GENERALIZED_ALPHA
        alpha_m, alpha_f, beta, gamma = generalized_alpha_parameters(scene.rho_infinity)
    return Solver(
        method=method,
        alpha_m=alpha_m,
        alpha_f=alpha_f,
        beta=beta,
        gamma=gamma,
        newton_tol=float(scene.newton_tol),
        newton_max_iter=int(scene.newton_max_iter),
        dt=float(scene.dt),
        dt_min=float(scene.dt_min),
        adaptive=bool(scene.adaptive),
        growth=STEP_GROWTH,
        rtol=float(scene.step_rtol) if scene.adaptive else 0.0,
        atol=float(scene.atol),
    )


@kernel
def carries_acceleration(solver):
    """The method carries the acceleration ``a`` from step to step (generalized-alpha)."""
    return solver.method != METHOD_BACKWARD_EULER


@kernel
def coefficients(solver, h):
    """``(c_M, c_x, c_v, alpha_m)`` of a step ``h`` (s): the Jacobian is ``c_M M - c_x dF/dx - c_v
    dF/dv``; a constant extra force ``F`` moves a free node of mass ``m`` by ``F / (c_M m)``."""
    if solver.method == METHOD_BACKWARD_EULER:
        return 1.0 / (h * h), 1.0, 1.0 / h, 0.0
    c_x = 1.0 - solver.alpha_f
    c_mass = (1.0 - solver.alpha_m) / (solver.beta * h * h)
    c_v = c_x * solver.gamma / (solver.beta * h)
    return c_mass, c_x, c_v, solver.alpha_m


@kernel(inline="always")
def time_tolerance(solver):
    """Times (s) closer than this are the same time to the step control (``1e-9 dt``)."""
    return 1e-9 * solver.dt


@kernel
def force_time(solver, stop, h):
    """The time (s) at which a step of size ``h`` ending at ``stop`` evaluates its forces, where a
    load that changes in time is taken: the step's end for backward Euler, ``t_{n+1-alpha_f} = stop -
    alpha_f h`` for generalized-alpha."""
    return stop - solver.alpha_f * h


@kernel
def arrival_factor(solver):
    """Reaction impulse per unit momentum that stops a node arriving at a ground: 1 for backward
    Euler, ``(1 - alpha_m) / beta`` for generalized-alpha (whose Newmark update reflects the node's
    normal velocity before the contact phase puts it at rest)."""
    if solver.method == METHOD_BACKWARD_EULER:
        return 1.0
    return (1.0 - solver.alpha_m) / solver.beta


@kernel
def predict(solver, v0, a0, h, dx):
    """The predictor of the step's displacement ``dx`` (m): ``h v0`` (backward Euler), ``h v0 +
    h^2 a0 / 2`` (generalized-alpha)."""
    for i in range(dx.shape[0]):
        for d in range(2):
            dx[i, d] = h * v0[i, d]
            if solver.method != METHOD_BACKWARD_EULER:
                dx[i, d] += 0.5 * h * h * a0[i, d]


@kernel
def kinematics(solver, x0, v0, a0, h, x1, v1, a1, ws):
    """From the step's displacement ``ws.dx``: ``x1``, ``v1``, ``a1`` and the force evaluation point
    ``ws.xe``, ``ws.ve``. Working with the displacement (not ``x1``) keeps ``a1`` free of the
    cancellation ``x1 - x0``, whose round-off would grow like ``1 / h^2``."""
    n = x1.shape[0]
    dx = ws.dx
    xe = ws.xe
    ve = ws.ve
    if solver.method == METHOD_BACKWARD_EULER:
        for i in range(n):
            for d in range(2):
                x1[i, d] = x0[i, d] + dx[i, d]
                v1[i, d] = dx[i, d] / h
                a1[i, d] = (dx[i, d] - h * v0[i, d]) / (h * h)
                xe[i, d] = x1[i, d]
                ve[i, d] = v1[i, d]
        return
    beta = solver.beta
    gamma = solver.gamma
    af = solver.alpha_f
    for i in range(n):
        for d in range(2):
            x1[i, d] = x0[i, d] + dx[i, d]
            a1[i, d] = (dx[i, d] - h * v0[i, d]) / (beta * h * h) - (0.5 - beta) / beta * a0[i, d]
            v1[i, d] = v0[i, d] + h * ((1.0 - gamma) * a0[i, d] + gamma * a1[i, d])
            xe[i, d] = x0[i, d] + (1.0 - af) * dx[i, d]
            ve[i, d] = (1.0 - af) * v1[i, d] + af * v0[i, d]


@kernel
def error_coefficient(solver):
    """``c`` of the estimate ``e = c h^2 (a1 - a0)`` (generalized-alpha: ``beta - 1/6``) or ``e = c h^2 a1``
    (backward Euler: 1/2)."""
    if solver.method == METHOD_BACKWARD_EULER:
        return 0.5
    return solver.beta - 1.0 / 6.0


@kernel
def error_exponent(solver):
    """``1 / (p + 1)``: how the estimate's ratio to the tolerance maps to a step-size factor."""
    if solver.method == METHOD_BACKWARD_EULER:
        return 0.5
    return 1.0 / 3.0


@kernel
def error_start_weight(solver):
    """Weight of the start acceleration ``a0`` in the local error estimate ``e = c h^2 (a1 - w a0)``:
    0 for backward Euler, 1 for generalized-alpha."""
    if solver.method == METHOD_BACKWARD_EULER:
        return 0.0
    return 1.0
