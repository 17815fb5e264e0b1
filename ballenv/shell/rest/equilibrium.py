"""Static equilibrium of a shell under its gas and constant point loads: Newton's method with a
backtracking line search on the total potential ``Pi`` (potential.py), the exact Hessian solved by
the envelope Cholesky (envelope.py).

Each iteration solves ``(K + tau I) dx = -grad Pi`` over the free degrees of freedom, with ``K`` the
exact Hessian (element matrices plus the gas's rank-one term by Sherman-Morrison) and ``tau = 0``
unless ``K`` is not positive definite (then the smallest ``tau`` of ``1e-8, 1e-6, ...`` times the
mean diagonal that makes it so). The step ``x + alpha dx`` takes the largest ``alpha`` of ``1, 1/2,
...`` that lowers ``Pi`` by at least ``1e-4 alpha |grad Pi . dx|`` (Armijo), or, where the change of
``Pi`` is below its rounding, that lowers ``|grad Pi|``. It stops when the largest free component
of ``grad Pi`` is at most ``tol E h l`` (N; ``l`` the mean rest edge length: the force of a unit
strain over an edge), and raises :class:`EquilibriumError` if that takes more than ``max_iter``
iterations or the line search finds no step.

Without ``fixed``, the rigid motion is removed by six statically determinate constraints
(:func:`determinate_support`), which carry no force when the loads are in balance (checked).
"""

from collections.abc import Mapping, Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..scene import ATMOSPHERIC_PRESSURE, Shell
from ..skin import potential
from ..skin.gas import gauge_pressure, volume
from ..skin.model import ShellModel, Workspace, build_model, build_workspace, initial_state
from ..solve import envelope

SHIFTS = (0.0, 1e-8, 1e-6, 1e-4, 1e-2, 1.0)  # tau / mean diagonal, tried in order
ARMIJO = 1e-4
HALVINGS = 40


class EquilibriumError(RuntimeError):
    """Newton's method found no equilibrium."""


class Equilibrium(NamedTuple):
    """An equilibrium: positions ``x`` (V, 3) m, gauge ``pressure`` (Pa), ``volume`` (m^3), Newton
    ``iterations`` and the final ``residual`` (N, largest free component of the gradient)."""

    x: NDArray[np.float64]
    pressure: float
    volume: float
    iterations: int
    residual: float


class Problem(NamedTuple):
    """What one equilibrium solve reads."""

    model: ShellModel
    ws: Workspace
    env: envelope.Envelope
    loads: NDArray[np.float64]  # (V, 3) N
    free: NDArray[np.bool_]  # (V, 3)


def determinate_support(x: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Free mask (V, 3) fixing six components: all of the vertex of largest x, y and z of the one
    of smallest x, z of the one of largest y (a 3-2-1 support of a sphere)."""
    free = np.ones(x.shape, dtype=np.bool_)
    free[int(np.argmax(x[:, 0]))] = False
    free[int(np.argmin(x[:, 0])), 1:] = False
    free[int(np.argmax(x[:, 1])), 2] = False
    return free


def load_array(
    point_loads: Mapping[int, ArrayLike] | ArrayLike | None, n_vertices: int
) -> NDArray[np.float64]:
    """Point loads (N) as a (V, 3) array, from None, a (V, 3) array or a mapping vertex -> 3-vector."""
    loads = np.zeros((n_vertices, 3))
    if point_loads is None:
        return loads
    if isinstance(point_loads, Mapping):
        for vertex, force in point_loads.items():
            if not (isinstance(vertex, (int, np.integer)) and 0 <= vertex < n_vertices):
                valid = f"must be an integer in [0, {n_vertices - 1}]"
                raise ValueError(f"point_loads: vertex {vertex!r} is out of range: {valid}")
            loads[vertex] += np.asarray(force, dtype=np.float64).reshape(3)
    else:
        loads[:] = np.asarray(point_loads, dtype=np.float64).reshape(n_vertices, 3)
    if not np.all(np.isfinite(loads)):
        raise ValueError("point_loads must be finite (N)")
    return loads


def free_mask(
    fixed: Sequence[int] | ArrayLike | None, x: NDArray[np.float64], loads: NDArray[np.float64]
) -> NDArray[np.bool_]:
    """The free components (V, 3): all but those ``fixed`` (vertex indices, or a (V, 3) boolean mask
    of fixed components); with None, the determinate support, the loads checked to be in balance."""
    if fixed is None:
        force = loads.sum(axis=0)
        moment = np.cross(x - x.mean(axis=0), loads).sum(axis=0)
        scale = np.abs(loads).sum() * (1.0 + np.ptp(x))
        if np.abs(force).max() > 1e-9 * scale or np.abs(moment).max() > 1e-9 * scale:
            raise ValueError("point_loads are not in balance (net force or moment): give fixed= supports")
        return determinate_support(x)
    mask = np.asarray(fixed)
    if mask.dtype == np.bool_:
        if mask.shape != x.shape:
            raise ValueError(f"fixed: a boolean mask must have shape {x.shape}, not {mask.shape}")
        return ~mask
    free = np.ones(x.shape, dtype=np.bool_)
    vertices = mask.astype(np.int64).ravel()
    if vertices.size and (vertices.min() < 0 or vertices.max() >= len(x)):
        raise ValueError(f"fixed: vertices must be in [0, {len(x) - 1}]")
    free[vertices] = False
    return free


def newton_direction(
    problem: Problem,
    x: NDArray[np.float64],
    grad: NDArray[np.float64],
    base: NDArray[np.float64] | None = None,
) -> NDArray[np.float64]:
    """The Newton correction ``dx`` (m) at ``x`` with gradient ``grad`` (module doc); ``base``
    (V, 3), a diagonal added to the Hessian (N/m: a mass term, a barrier's curvature), or None."""
    m, ws, env = problem.model, problem.ws, problem.env
    s = potential.hessian(m, ws, x)
    diagonal = np.zeros_like(x)
    mean = np.mean([np.abs(np.diagonal(ws.tri_hess, axis1=1, axis2=2)).mean(), m.kb])
    for tau in SHIFTS:
        diagonal[:] = tau * mean
        if base is not None:
            diagonal += base
        envelope.assemble(env, m.triangles, ws.tri_hess, m.hinges, ws.hinge_hess, diagonal, problem.free)
        if envelope.cholesky(env):
            dx = np.zeros_like(x)
            envelope.solve_rank_one(env, problem.free, s, ws.dvol, -grad, dx, np.zeros_like(x))
            return dx
    raise EquilibriumError("the Hessian stays indefinite after a shift of its mean diagonal")


def line_search(
    problem: Problem, x: NDArray[np.float64], dx: NDArray[np.float64], grad: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(x + alpha dx, its gradient)`` for the first accepted ``alpha`` (module doc)."""
    m, ws, loads, free = problem.model, problem.ws, problem.loads, problem.free
    e0 = potential.energy(m, ws, x, loads)
    slope = float(np.sum(grad * dx))
    rounding = 1e-13 * (abs(m.absolute_pressure[0]) * m.rest_volume + np.abs(loads * x).sum() + abs(e0))
    g0 = np.abs(grad[free]).max()
    trial_grad = np.zeros_like(x)
    alpha = 1.0
    for _ in range(HALVINGS):
        trial = x + alpha * dx
        e = potential.energy(m, ws, trial, loads)
        if np.isfinite(e):
            if e <= e0 - ARMIJO * alpha * abs(slope):
                potential.gradient(m, ws, trial, loads, trial_grad)
                return trial, trial_grad
            if abs(e - e0) <= rounding:
                potential.gradient(m, ws, trial, loads, trial_grad)
                if np.abs(trial_grad[free]).max() < g0:
                    return trial, trial_grad
        alpha *= 0.5
    raise EquilibriumError(f"the line search found no step that lowers the potential (|grad| = {g0:.3e} N)")


def solve(
    problem: Problem, x: NDArray[np.float64], tol: float, max_iter: int
) -> tuple[NDArray[np.float64], int, float]:
    """Newton's iteration from ``x``: (equilibrium, iterations, residual in N)."""
    m, free = problem.model, problem.free
    edge = np.linalg.norm(m.rest[m.edges[:, 1]] - m.rest[m.edges[:, 0]], axis=1).mean()
    youngs = m.mu * 2.0 * (1.0 + m.lam / (m.lam + 2.0 * m.mu))  # E from the plane-stress constants
    goal = tol * youngs * m.thickness * edge
    grad = np.zeros_like(x)
    potential.gradient(m, problem.ws, x, problem.loads, grad)
    for iteration in range(max_iter + 1):
        residual = float(np.abs(grad[free]).max()) if free.any() else 0.0
        if residual <= goal:
            return x, iteration, residual
        if iteration == max_iter:
            break
        dx = newton_direction(problem, x, grad)
        x, grad = line_search(problem, x, dx, grad)
    raise EquilibriumError(
        f"no equilibrium after {max_iter} Newton iterations: residual {residual:.3e} N > {goal:.3e} N"
    )


def equilibrium(
    shell: Shell,
    point_loads: Mapping[int, ArrayLike] | ArrayLike | None = None,
    fixed: Sequence[int] | ArrayLike | None = None,
    gas_exponent: float = 1.0,
    atmospheric_pressure: float = ATMOSPHERIC_PRESSURE,
    x0: ArrayLike | None = None,
    tol: float = 1e-10,
    max_iter: int = 50,
) -> Equilibrium:
    """The static equilibrium of ``shell`` (centred at its ``position``) under its gas (gas law of
    ``gas_exponent``, ``atmospheric_pressure`` Pa) and constant ``point_loads`` (N; a (V, 3) array or
    a mapping vertex -> force), with the ``fixed`` vertices (indices) or components ((V, 3) boolean
    mask) held where they start; started from ``x0`` (V, 3) m or the rest shape. See the module doc."""
    model = build_model(shell, gas_exponent, atmospheric_pressure)
    x = initial_state(shell, model)[0] if x0 is None else np.array(x0, dtype=np.float64).reshape(-1, 3)
    if x.shape != model.rest.shape or not np.all(np.isfinite(x)):
        raise ValueError(f"x0 must be finite positions of shape {model.rest.shape} (m)")
    loads = load_array(point_loads, len(x))
    free = free_mask(fixed, x, loads)
    env = envelope.build_envelope(len(x), model.triangles, model.hinges)
    problem = Problem(model, build_workspace(model), env, loads, free)
    x, iterations, residual = solve(problem, x, tol, max_iter)
    vol = volume(x, model.triangles)
    return Equilibrium(x, float(gauge_pressure(model, vol)), float(vol), iterations, residual)
