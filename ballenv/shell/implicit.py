"""One implicit backward-Euler step of a shell under its gas, gravity and a flat ground.

The step of size ``dt`` (s) from positions ``x0`` (m) and velocities ``v0`` (m/s) is the minimiser of
the incremental potential (J)::

    Phi(x) = sum_i m_i / (2 dt^2) |x_i - x0_i - dt v0_i|^2 + Pi(x) + sum_i m_i g z_i + B(x)

(``Pi`` stretching + bending + gas, potential.py; ``g`` m/s^2 along -z; ``B`` the ground's barrier,
ground.py), whose stationarity is backward Euler, ``M (v1 - v0) / dt = -grad (Pi + gravity + B)(x1)``
with ``v1 = (x1 - x0) / dt``. Newton's method from ``x0 + dt v0`` minimises it: the exact Hessian
``M / dt^2 + K + d2B`` (the gas's rank-one term by Sherman-Morrison, equilibrium.newton_direction),
each correction first cut so that no vertex reaches the ground (ground.max_step), then halved until
``Phi`` drops (Armijo) or, below ``Phi``'s rounding, ``|grad Phi|`` does. It stops when every
vertex's residual acceleration ``|grad Phi|_i / m_i`` is below ``tol (g + R / dt^2)`` (m/s^2);
otherwise :class:`equilibrium.EquilibriumError`.

Gravity is a constant point load ``-m_i g`` on every vertex, so the centre of mass falls exactly as
backward Euler says while nothing touches: ``z_n = z_0 - g dt^2 n (n + 1) / 2``.
"""

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from . import envelope, ground, potential
from .equilibrium import ARMIJO, HALVINGS, EquilibriumError, Problem, newton_direction
from .model import ShellModel, build_workspace
from .scene import Shell


class StepSettings(NamedTuple):
    """dt (s), gravity g (m/s^2, along -z), the ground's height (m; -inf: none), the barrier's reach
    dhat (m) and stiffness kappa (N/m), Newton's tolerance and iteration limit."""

    dt: float
    gravity: float = 9.81
    ground_height: float = -np.inf
    dhat: float = 1e-3
    kappa: float = 1e4
    tol: float = 1e-10
    max_iter: int = 30


def step_problem(model: ShellModel, settings: StepSettings) -> Problem:
    """What the steps of ``model`` read: gravity as point loads (N), every component free."""
    loads = np.zeros_like(model.rest)
    loads[:, 2] = -model.mass * settings.gravity
    env = envelope.build_envelope(len(model.rest), model.triangles, model.hinges)
    return Problem(model, build_workspace(model), env, loads, np.ones(model.rest.shape, dtype=np.bool_))


def incremental(
    problem: Problem, settings: StepSettings, target: NDArray[np.float64], x: NDArray[np.float64]
) -> float:
    """Phi(x) (J) for the inertial target ``x0 + dt v0``."""
    m = problem.model.mass[:, None]
    inertia = 0.5 * float(np.sum(m * (x - target) ** 2)) / settings.dt**2
    barrier = ground.barrier_energy(x, settings.ground_height, settings.dhat, settings.kappa)
    return inertia + potential.energy(problem.model, problem.ws, x, problem.loads) + barrier


def incremental_gradient(
    problem: Problem, settings: StepSettings, target: NDArray[np.float64], x: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(grad Phi (N), the diagonal M / dt^2 + d2B (N/m))`` at ``x``."""
    m = np.repeat(problem.model.mass[:, None], 3, axis=1)
    grad = np.zeros_like(x)
    potential.gradient(problem.model, problem.ws, x, problem.loads, grad)
    grad += m * (x - target) / settings.dt**2
    diagonal = m / settings.dt**2
    ground.add_barrier(x, settings.ground_height, settings.dhat, settings.kappa, grad, diagonal)
    return grad, diagonal


def search(
    problem: Problem, settings: StepSettings, target: NDArray[np.float64], x: NDArray[np.float64],
    dx: NDArray[np.float64], grad: NDArray[np.float64],
) -> NDArray[np.float64]:  # fmt: skip
    """``x + alpha dx`` for the first accepted ``alpha`` (module doc)."""
    e0 = incremental(problem, settings, target, x)
    slope = abs(float(np.sum(grad * dx)))
    rounding = 1e-13 * (problem.model.absolute_pressure * problem.model.rest_volume + abs(e0))
    g0 = np.abs(grad).max()
    alpha = ground.max_step(x, dx, settings.ground_height)
    for _ in range(HALVINGS):
        trial = x + alpha * dx
        e = incremental(problem, settings, target, trial)
        if e <= e0 - ARMIJO * alpha * slope:
            return trial
        if (
            abs(e - e0) <= rounding
            and np.abs(incremental_gradient(problem, settings, target, trial)[0]).max() < g0
        ):
            return trial
        alpha *= 0.5
    raise EquilibriumError(f"the step's line search found no descent (|grad| = {g0:.3e} N)")


def step(
    problem: Problem, settings: StepSettings, x0: NDArray[np.float64], v0: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], int]:
    """One backward-Euler step: ``(x1, v1, Newton iterations)`` (module doc)."""
    dt = settings.dt
    target = x0 + dt * v0
    x = target.copy()
    x[:, 2] = np.maximum(x[:, 2], x0[:, 2] - ground.CCD_SAFETY * (x0[:, 2] - settings.ground_height))
    radius = float(np.abs(problem.model.rest).max())
    goal = settings.tol * (settings.gravity + radius / dt**2)
    mass = problem.model.mass[:, None]
    for iteration in range(settings.max_iter + 1):
        grad, diagonal = incremental_gradient(problem, settings, target, x)
        if np.abs(grad / mass).max() <= goal:
            return x, (x - x0) / dt, iteration
        if iteration == settings.max_iter:
            break
        dx = newton_direction(problem, x, grad, diagonal)
        x = search(problem, settings, target, x, dx, grad)
    raise EquilibriumError(f"no step after {settings.max_iter} Newton iterations")


def total_energy(
    problem: Problem, settings: StepSettings, x: NDArray[np.float64], v: NDArray[np.float64]
) -> float:
    """Kinetic + stretching + bending + gas + gravity + barrier energy (J)."""
    kinetic = 0.5 * float(np.sum(problem.model.mass[:, None] * v * v))
    barrier = ground.barrier_energy(x, settings.ground_height, settings.dhat, settings.kappa)
    return kinetic + potential.energy(problem.model, problem.ws, x, problem.loads) + barrier


def shell_kappa(shell: Shell) -> float:
    """A barrier stiffness (N/m) for ``shell``: its membrane stiffness ``E h``."""
    return shell.youngs_modulus * shell.thickness
