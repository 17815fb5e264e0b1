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
"""

import math

import numpy as np
from numba import njit

from .elastic import bend_force, bend_jacobian, stretch_force, stretch_jacobian
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
from .model import METHOD_BACKWARD_EULER

STATUS_DONE = 0
STATUS_BUFFER_FULL = 1
STATUS_STEP_TOO_SMALL = 2

# counters: accepted steps, rejected steps, Newton iterations (linear solves), fixed-grid index
COUNT_STEPS = 0
COUNT_REJECTED = 1
COUNT_NEWTON = 2
COUNT_GRID = 3
N_COUNTERS = 4

# clock: time (s), current step size (s)
CLOCK_T = 0
CLOCK_H = 1


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
def newton_ring(model, solver, r, x0, v0, a0, h, x1, v1, a1, ws):
    """Solve one implicit step of ring ``r``; ``x1, v1, a1`` receive the new state.

    Returns the number of Newton corrections (>= 0), or -1 if the step must be rejected.
    """
    n = x0.shape[0]
    m = model.node_mass[r]
    if solver.method == METHOD_BACKWARD_EULER:
        c_mass = 1.0 / (h * h)
        c_x = 1.0
        c_v = 1.0 / h
        am = 0.0
    else:
        c_mass = (1.0 - solver.alpha_m) / (solver.beta * h * h)
        c_x = 1.0 - solver.alpha_f
        c_v = (1.0 - solver.alpha_f) * solver.gamma / (solver.beta * h)
        am = solver.alpha_m
    dx = ws.dx
    for i in range(n):
        for d in range(2):
            dx[i, d] = h * v0[i, d]
            if solver.method != METHOD_BACKWARD_EULER:
                dx[i, d] += 0.5 * h * h * a0[i, d]
    res = ws.res
    f = ws.force
    for it in range(solver.newton_max_iter + 1):
        _kinematics(solver, x0, v0, a0, h, x1, v1, a1, ws)
        ring_force(model, r, ws.xe, ws.ve, f)
        worst = 0.0
        scale = 0.0
        for i in range(n):
            for d in range(2):
                inertia = m * ((1.0 - am) * a1[i, d] + am * a0[i, d])
                val = inertia - f[i, d]
                res[2 * i + d] = val
                if not math.isfinite(val):
                    return -1
                worst = max(worst, abs(val))
                scale = max(scale, abs(inertia) + abs(f[i, d]))
        if worst <= solver.newton_tol * scale:
            return it
        if it == solver.newton_max_iter:
            return -1
        rank = ring_jacobian(model, r, ws.xe, ws.ve, c_mass, c_x, c_v, ws)
        if not solve_band_low_rank(ws.band, ws.pos, ws.u, ws.w, rank, res, ws.work, ws.cap, ws.coef):
            return -1
        step = 0.0
        size = 0.0
        for i in range(n):
            for d in range(2):
                delta = res[2 * i + d]
                if not math.isfinite(delta):
                    return -1
                dx[i, d] -= delta
                step = max(step, abs(delta))
                size = max(size, abs(x0[i, d]) + abs(dx[i, d]))
        if step <= 1e-13 * size:
            _kinematics(solver, x0, v0, a0, h, x1, v1, a1, ws)
            return it + 1
    return -1


@njit(cache=True)
def initial_acceleration(model, x, v, a, ws):
    """``a = F(x, v) / m`` for every ring (the generalized-alpha start value)."""
    for r in range(x.shape[0]):
        ring_force(model, r, x[r], v[r], ws.force)
        for i in range(x.shape[1]):
            for d in range(2):
                a[r, i, d] = ws.force[i, d] / model.node_mass[r]


@njit(cache=True)
def try_step(model, solver, x, v, a, h, x1, v1, a1, ws):
    """One step of every ring; returns total Newton corrections, or -1 if any ring fails."""
    total = 0
    for r in range(x.shape[0]):
        its = newton_ring(model, solver, r, x[r], v[r], a[r], h, x1[r], v1[r], a1[r], ws)
        if its < 0:
            return -1
        total += its
    return total


@njit(cache=True)
def _record(model, k, t, x, v, out_t, out_x, out_v, out_p):
    out_t[k] = t
    out_x[k] = x
    out_v[k] = v
    for r in range(x.shape[0]):
        out_p[k, r] = ring_pressure(model, r, x[r])


@njit(cache=True)
def advance(
    model,
    solver,
    ws,
    x,
    v,
    a,
    x1,
    v1,
    a1,
    clock,
    counters,
    t_pause,
    t_end,
    output_dt,
    out_t,
    out_x,
    out_v,
    out_p,
    n_out,
):
    """Step the state ``x, v, a`` (R, N, 2) from ``clock[CLOCK_T]`` to ``t_end``, pausing (returning)
    after the first step that reaches ``t_pause`` (<= ``t_end``; for progress reports).

    Records the state into the ``out_*`` buffers from index ``n_out`` on: every accepted step if
    ``output_dt == 0``, else exactly at multiples of ``output_dt`` (steps are shortened to land on
    them). Returns ``(status, n_out)``; status is STATUS_DONE, STATUS_BUFFER_FULL (call again with
    room) or STATUS_STEP_TOO_SMALL (the step fell below ``dt_min``: the state is the last accepted).
    """
    capacity = out_t.shape[0]
    while clock[CLOCK_T] < t_pause:
        if n_out >= capacity:
            return STATUS_BUFFER_FULL, n_out
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
        its = try_step(model, solver, x, v, a, h, x1, v1, a1, ws)
        if its < 0:
            counters[COUNT_REJECTED] += 1
            clock[CLOCK_H] = 0.5 * h
            if clock[CLOCK_H] < solver.dt_min:
                return STATUS_STEP_TOO_SMALL, n_out
            continue
        counters[COUNT_STEPS] += 1
        counters[COUNT_NEWTON] += its
        x[:] = x1
        v[:] = v1
        a[:] = a1
        clock[CLOCK_T] = stop
        if solver.adaptive:
            clock[CLOCK_H] = min(clock[CLOCK_H] * solver.growth, solver.dt)
        elif at_grid:
            counters[COUNT_GRID] += 1
            clock[CLOCK_H] = solver.dt
        if output_dt == 0.0 or at_out or at_end:
            _record(model, n_out, stop, x, v, out_t, out_x, out_v, out_p)
            n_out += 1
    return STATUS_DONE, n_out


def empty_state(n_rings, n_nodes):
    """Zeroed (R, N, 2) arrays for a state and a trial state."""
    return [np.zeros((n_rings, n_nodes, 2)) for _ in range(6)]
