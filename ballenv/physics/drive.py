"""Actuation spread over time, delivered step by step: gas ramps and spread impulses.

Actuation at one instant (:mod:`.actuation`: ``set_rest_pressure``, ``apply_impulse``) changes a
ring between steps at once: a staircase of gas amounts at a controller's rate rings the ring's
breathing mode, and a paddle's whole strike lands in one instant. A :class:`model.Drive` spreads
them over time; the stepper calls three phases, each a no-op (pruned when numba compiles) for a
model without a drive (``Model.drive`` None):

* :func:`drive_landing`: steps land on the start and end of every ramp and push window, as they
  land on output times (the step is shortened, its size control is not);
* :func:`drive_step`, before every trial step ``[t, t + h]``, actuates the start state:

  - *gas ramp*: the ring holds the amount of the ramp at the step's force-evaluation time
    ``t_f = t + h - alpha_f h`` (:func:`integrator.force_time`), linear in time,
    ``C(t_f) = C_0 + (t_f - t_0) / (t_1 - t_0) (C_1 - C_0)``; the end of the step for backward
    Euler, the time generalized-alpha evaluates every load at (``F`` at ``t_{n+1-alpha_f}``, as
    Chung & Hulbert evaluate a time-dependent load), so the ramp is stepped to the integrator's own
    order. Its rest energy follows (the inflated circle of that amount: :func:`actuation.rest_pressure_of`);
  - *spread impulse*: the nodes sharing it receive, as a velocity change, the part of its momentum
    ``J`` that falls in the step, ``J (f(t + h) - f_done)``, ``f(t) = (t - t_s) / tau`` clamped to
    [0, 1], ``f_done`` what was delivered so far, which becomes ``f(t + h)``. A velocity change at
    the start of a step is exact in momentum for any integrator (the step's internal forces sum to
    zero, and Newton's iteration keeps that sum, which is linear in the unknowns, to round-off), so
    the momentum delivered is ``J`` times the sum of the fractions, which telescopes to ``J`` exactly
    once a step ends at ``t_s + tau``, and nothing follows. For backward Euler the kick at the
    start of a step is the same step as a constant force ``J (f(t + h) - f(t)) / h`` during it;
    with steps landing on ``t_s + tau`` a strike is a constant force over its duration. (A force
    inside generalized-alpha's residual would not give ``J``: its carried acceleration spreads a
    load's momentum over the following steps.)

  then recounts the ring's carried energy (:func:`actuation.recount_energy`): its energy budget is
  credited with ``E(x, v; C(t_f), v + dv) - E(x, v; C_held, v)`` at the start state, the pump's and
  the push's work. A trial step that is rejected leaves its actuation in place; the retry actuates
  again from there, so the credits telescope to those of the accepted steps;
* :func:`drive_accepted`, after an accepted step that reaches a ramp's end: the ring then holds the
  ramp's end amount exactly (:func:`actuation.set_rest_pressure`, credited the same way; for
  generalized-alpha the last step's amount was that of ``t_1 - alpha_f h``), so at the end of a
  ramp the amount is its setpoint to the bit.

Why the credit is the work done: the ring's energy (:func:`energy.free_energy`) changes only
through steps at a fixed gas amount, in which the gas is a potential (an integrator conserves or
dissipates it; this is what the energy guard checks), and through these changes at a fixed state.
The gas energy ``U(A; C) = -b (C phi(A) - p_atm A)`` (``phi = ln`` for ``k = 1``) depends on the
amount only through ``-b C phi(A)``, so the credit ``-b (C_new - C_old) phi(A(x))`` is the energy
the pump puts in at the ring's present area; ``phi``'s reference (the unit of area) is a constant
per amount that cancels in every comparison the guard makes (both sides of a step hold the same
amount). The push's credit is the kinetic energy its velocity change adds.
"""

import math

from .actuation import ramp_value, recount_energy, rest_pressure_of, set_gas_amount, set_rest_pressure
from .integrator import force_time
from .jit import kernel
from .layout import (
    PUSH_DELIVERED,
    PUSH_T_END,
    PUSH_T_START,
    PUSH_X,
    PUSH_Y,
    RAMP_AMOUNT_END,
    RAMP_AMOUNT_START,
    RAMP_PRESSURE_END,
    RAMP_PRESSURE_START,
    RAMP_T_END,
    RAMP_T_START,
)


@kernel
def time_tolerance(solver):
    """Times (s) closer than this are the same time (as in ``stepper.step_end``)."""
    return 1e-9 * solver.dt


@kernel
def drive_landing(solver, t, drive):
    """The first start or end (s) of a ramp or push window after ``t`` (s), where the next step
    lands; inf without one (or without a drive)."""
    if drive is None:
        return math.inf
    eps = time_tolerance(solver)
    land = math.inf
    for r in range(drive.ramp.shape[0]):
        for mark in (
            drive.ramp[r, RAMP_T_START], drive.ramp[r, RAMP_T_END],
            drive.push[r, PUSH_T_START], drive.push[r, PUSH_T_END],
        ):  # fmt: skip
            if mark > t + eps:
                land = min(land, mark)
    return land


@kernel
def drive_step(model, solver, state, t, stop, ws, drive):
    """Actuate every ring's start state ``state`` for the trial step from ``t`` to ``stop`` (s):
    its gas ramp's amount at the step's force-evaluation time and its spread impulse's share (see
    module doc), then recount its carried energy. Nothing for a ring with neither under way."""
    if drive is None:
        return
    h = stop - t
    for r in range(drive.ramp.shape[0]):
        ramping = drive.ramp[r, RAMP_T_END] > t
        pushing = drive.push[r, PUSH_T_END] > t
        if ramping:
            ramp_gas(model, r, force_time(solver, stop, h), state.x.shape[1], ws, drive)
        if pushing:
            push_share(model, r, stop, state.v[r], drive)
        if ramping or pushing:
            recount_energy(model, r, state.x[r], state.v[r], state.energy[r], ws)


@kernel
def ramp_gas(model, r, t, n, ws, drive):
    """Ring ``r`` (``n`` nodes) holds its ramp's gas amount of time ``t`` (s), with that amount's
    rest energy (its gauge pressure at rest solved from the ramp's linear guess)."""
    ramp = drive.ramp[r]
    amount = ramp_value(ramp, RAMP_AMOUNT_START, RAMP_AMOUNT_END, t)
    guess = ramp_value(ramp, RAMP_PRESSURE_START, RAMP_PRESSURE_END, t)
    set_gas_amount(model, r, amount, rest_pressure_of(model, r, amount, guess, n), n, ws)


@kernel
def push_share(model, r, stop, v, drive):
    """Add to ring ``r``'s velocities ``v`` (m/s) the share of its spread impulse up to ``stop`` (s):
    ``J (f(stop) - f_done) / (count m)`` on each of its ``count`` nodes; ``f_done = f(stop)``."""
    push = drive.push[r]
    pushed = drive.pushed[r]
    t0 = push[PUSH_T_START]
    done = min(1.0, max(0.0, (stop - t0) / (push[PUSH_T_END] - t0)))
    share = done - push[PUSH_DELIVERED]
    push[PUSH_DELIVERED] = done
    count = 0
    for i in range(pushed.shape[0]):
        count += pushed[i]
    if count == 0:
        return
    dvx = push[PUSH_X] * share / (count * model.node_mass[r])
    dvy = push[PUSH_Y] * share / (count * model.node_mass[r])
    for i in range(pushed.shape[0]):
        if pushed[i]:
            v[i, 0] += dvx
            v[i, 1] += dvy


@kernel
def drive_accepted(model, solver, state, stop, ws, drive):
    """After an accepted step ending at ``stop`` (s): a ring whose gas ramp ends there holds the
    ramp's end amount, exactly as :func:`actuation.set_rest_pressure` sets it (the difference, for
    generalized-alpha that of ``alpha_f h`` of the ramp, credited to its energy budget); the ramp is
    then off. (A push needs nothing: its last step delivered the rest.)"""
    if drive is None:
        return
    eps = time_tolerance(solver)
    for r in range(drive.ramp.shape[0]):
        ramp = drive.ramp[r]
        if ramp[RAMP_T_END] > -math.inf and stop >= ramp[RAMP_T_END] - eps:
            ramp[RAMP_T_END] = -math.inf
            x, v = state.x[r], state.v[r]
            set_rest_pressure(model, r, ramp[RAMP_PRESSURE_END], x, v, state.energy[r], ws)
