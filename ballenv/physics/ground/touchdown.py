"""Touchdown location: under error control (``Scene.rtol`` > 0, adaptive) with the default
``contact_error = "impulse"``, a step of a ring in flight ends where its first node reaches a
ground, not somewhere past it. (Under "doubling" the arrival error of
:mod:`ballenv.physics.step.contact_error` bounds the same overshoot.)

An implicit step whose end has a node newly on a ground holds that node there through the whole
step: its neighbours feel the reaction from the step's start, though the node touched only at a time
``t_a`` into the step. Pushed by its neighbours with a force ``F`` (N) that the wall's compression
over the overshoot ``h - t_a`` sets, the ring takes a reaction impulse of about ``F h`` (N s) where
it should take ``F (h - t_a) / 2``: an excess the contact bound (``Scene.rtol M sqrt(g R)`` per
step) can let through on a heavy ball. Landing the step on the touch removes it.

The touch is predicted from the step's start (``touchdown_landing``): each node of a ring with no
node on a ground follows its velocity and gravity, relative to the ground's surface,

    phi + s t + q t^2 / 2 = 0,   s = (v - w) . n,   q = g . n,

(``phi`` (m) its distance to the ground along the normal ``n``, ``v`` and ``w`` (m/s) its and the
surface's velocities, ``g`` (m/s^2) gravity), whose first root is
``t_a = 2 phi / (-s + sqrt(s^2 - 2 q phi))``. The wall's vibration makes that approximate: a step
that ends short of the touch leaves a closer start for the next prediction. A touch predicted within
``MIN_FRACTION`` of the step (or ``dt_min``) is taken as the step's start and not landed on: the
node is then held for at most that fraction of the step too long.
"""

import math

from ..base.jit import kernel
from .contact import FREE, frame, surface_velocity
from .motion import ground_surfaces

MIN_FRACTION = 1e-3  # a touch predicted sooner than this fraction of the step is the step's start


@kernel
def first_touch(model, surface, x, v):
    """The time (s) until the first of a ring's nodes (positions ``x`` (m), velocities ``v`` (m/s),
    (N, 2)) reaches a ground (``surface``: the grounds now, rows ``base.layout.SURFACE``) on its ballistic
    path relative to the surface; inf if none approaches."""
    gx, gy = model.gravity[0], model.gravity[1]
    soonest = math.inf
    for i in range(x.shape[0]):
        for g in range(surface.shape[0]):
            nx, ny, phi = frame(surface, g, x[i, 0], x[i, 1])
            if phi <= 0.0:
                continue
            wx, wy = surface_velocity(surface, g, x[i, 0], x[i, 1])
            s = (v[i, 0] - wx) * nx + (v[i, 1] - wy) * ny
            q = gx * nx + gy * ny
            disc = s * s - 2.0 * q * phi
            if disc < 0.0:
                continue
            closing = math.sqrt(disc) - s
            if closing > 0.0:
                soonest = min(soonest, 2.0 * phi / closing)
    return soonest


@kernel
def touchdown_landing(model, solver, ws, state, t, h):
    """The time (s) a step of size ``h`` (s) from ``state`` at time ``t`` (s) lands on: the first
    predicted touch (:func:`first_touch`) of a ring with no node on a ground, if it falls inside the
    step and not within ``max(MIN_FRACTION h, dt_min)`` of its start; inf otherwise, or without error
    control. Writes the grounds at ``t`` to ``ws.surface_start``."""
    if solver.rtol <= 0.0 or not solver.adaptive or model.grounds.shape[0] == 0:
        return math.inf
    if ws.doubling is not None:  # (pruned by numba) its arrival error bounds the same overshoot
        return math.inf
    ground_surfaces(model.grounds, t, ws.surface_start)
    soonest = math.inf
    for r in range(state.x.shape[0]):
        airborne = True
        for i in range(state.x.shape[1]):
            if state.active[r, i] != FREE:
                airborne = False
                break
        if airborne:
            soonest = min(soonest, first_touch(model, ws.surface_start, state.x[r], state.v[r]))
    if max(MIN_FRACTION * h, solver.dt_min) < soonest < h:
        return t + soonest
    return math.inf
