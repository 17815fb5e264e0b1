"""Actuation spread over time, delivered step by step: gas ramps and spread impulses.

Actuation at one instant (:mod:`.actuation`: ``set_rest_pressure``, ``apply_impulse``) changes a
ring between steps at once: a staircase of gas amounts at a controller's rate rings the ring's
breathing mode, and a paddle's whole strike lands in one instant. A :class:`model.Drive` spreads
them over time (started by :func:`actuation.ramp_rest_pressure` and
:func:`actuation.spread_impulse`). ``stepper.advance`` takes the drive as its own argument and,
unless it is None (then numba prunes these calls and compiles none of this module), calls two
phases:

* :func:`drive_landing`: steps land on the start and end of every ramp and push window, as they
  land on output times (the step is shortened, its size control is not);
* :func:`drive_step`, before every trial step from ``t`` to ``t + h``, actuates the start state:

  - *gas ramp*: the ring holds the amount of the ramp at the step's force-evaluation time
    ``t_f = t + h - alpha_f h`` (:func:`integrator.force_time`), linear in time,
    ``C(t_f) = C_0 + (t_f - t_0) / (t_1 - t_0) (C_1 - C_0)``: the end of the step for backward
    Euler, and for generalized-alpha the time it evaluates every load at (``F`` at
    ``t_{n+1-alpha_f}``, as Chung & Hulbert take a time-dependent load), so the ramp is stepped to
    the integrator's own order. Once the ramp has ended (``t >= t_1``; the stepper also calls
    this phase with ``h = 0`` after each accepted step), the ring holds the ramp's end amount
    exactly, so from the end of a ramp on the amount is its setpoint to the bit (for
    generalized-alpha the last step held that of ``t_1 - alpha_f h``). The rest energy
    (``Model.rest_energy``) follows the amount (:func:`actuation.ramp_rest_energy`);
  - *spread impulse*: the nodes sharing it receive, as a velocity change, the part of its momentum
    ``J`` that falls in the step, ``J (f(t + h) - f_done)``, ``f(t) = (t - t_s) / tau`` clamped to
    [0, 1], ``f_done`` what was delivered so far, which becomes ``f(t + h)``. The momentum
    delivered is ``J`` times the sum of the fractions, which telescopes to ``J`` exactly once a
    step ends at ``t_s + tau``, and nothing follows; a velocity change at the start of a step is
    the same momentum for any integrator (the internal forces sum to zero whatever the state, so
    the residual's sum over nodes is linear in the unknowns and a full Newton correction zeroes
    it to round-off). For backward Euler the kick at the start of a step is the same step as a
    constant force ``J (f(t + h) - f(t)) / h`` during it; with steps landing on ``t_s + tau`` a
    strike is a constant force over its duration. (A force inside generalized-alpha's residual
    would not give ``J``: its carried acceleration spreads a load's momentum over the following
    steps.)

  then recounts the ring's carried energy (:func:`actuation.recount_energy`): its energy budget is
  credited with ``E(x, v + dv; C_new) - E(x, v; C_old)`` at the start state, the pump's and the
  push's work. A trial step that is rejected leaves its actuation in place; the retry actuates
  again from there, so the credits telescope to those of the accepted steps.

Why the credit is the work done: the ring's energy (:func:`energy.free_energy`) changes only
through steps at a fixed gas amount, in which the gas is a potential (an integrator conserves or
dissipates it; this is what the energy guard checks), and through these changes at a fixed state.
The gas energy ``U(A; C) = -b (C phi(A) - p_atm A)`` (``phi = ln`` for ``k = 1``, else
``A^(1-k) / (1-k)``; :func:`effects.gas.gas_energy`) depends on the amount only through
``-b C phi(A)``, so the credit ``-b (C_new - C_old) phi(A(x))`` is the energy the pump puts in at
the ring's present area; ``phi``'s reference (the unit of area) is a constant per amount that
cancels in every comparison the guard makes (both sides of a step hold the same amount). The
push's credit is the kinetic energy its velocity change adds.
"""

import math

from .actuation import ramp_fraction, ramp_rest_energy, recount_energy
from .integrator import force_time, time_tolerance
from .jit import kernel
from .layout import (
    PUSH_DELIVERED,
    PUSH_T_END,
    PUSH_T_START,
    PUSH_X,
    PUSH_Y,
    RAMP_AMOUNT_END,
    RAMP_AMOUNT_START,
    RAMP_REST_END,
    RAMP_T_END,
    RAMP_T_START,
)


@kernel
def drive_landing(solver, t, drive):
    """The first start or end (s) of a ramp or push window after ``t`` (s), where the next step
    lands; inf without one."""
    after = t + time_tolerance(solver)
    land = math.inf
    for r in range(drive.ramp.shape[0]):
        for mark in (
            drive.ramp[r, RAMP_T_START], drive.ramp[r, RAMP_T_END],
            drive.push[r, PUSH_T_START], drive.push[r, PUSH_T_END],
        ):  # fmt: skip
            if mark > after:
                land = min(land, mark)
    return land


@kernel
def drive_step(model, solver, state, t, stop, ws, drive):
    """Actuate every ring's start state ``state`` for the trial step from ``t`` to ``stop`` (s): its
    gas ramp's amount at the step's force-evaluation time (its end amount once it has ended) and
    its spread impulse's share (see module doc), then recount its carried energy. With ``stop ==
    t`` only what is due at ``t`` (a ramp that has ended)."""
    eps = time_tolerance(solver)
    for r in range(drive.ramp.shape[0]):
        ramp = drive.ramp[r]
        changed = False
        if ramp[RAMP_T_END] > -math.inf:
            if t >= ramp[RAMP_T_END] - eps:  # over: its end amount, and off
                model.gas_constant[r] = ramp[RAMP_AMOUNT_END]
                model.rest_energy[r] = ramp[RAMP_REST_END]
                ramp[RAMP_T_END] = -math.inf
                changed = True
            elif stop > t:
                s = ramp_fraction(ramp, force_time(solver, stop, stop - t))
                start = ramp[RAMP_AMOUNT_START]
                model.gas_constant[r] = start + s * (ramp[RAMP_AMOUNT_END] - start)
                model.rest_energy[r] = ramp_rest_energy(ramp, s)[0]
                changed = True
        if drive.push[r, PUSH_T_END] > t:
            changed |= push_share(drive.push[r], drive.pushed[r], model.node_mass[r], stop, state.v[r])
        if changed:
            recount_energy(model, r, state.x[r], state.v[r], state.energy[r], ws)


@kernel(inline="always")
def push_share(push, pushed, m, stop, v):
    """Add to a ring's velocities ``v`` (m/s; node mass ``m`` kg) the share of its spread impulse
    ``push`` (a ``layout.PUSH`` row) up to ``stop`` (s): ``J (f(stop) - f_done) / (count m)`` on
    each of the ``count`` nodes marked in ``pushed``; ``f_done = f(stop)``. Returns whether any
    share was given."""
    t0 = push[PUSH_T_START]
    done = min(1.0, max(0.0, (stop - t0) / (push[PUSH_T_END] - t0)))
    share = done - push[PUSH_DELIVERED]
    push[PUSH_DELIVERED] = done
    count = 0
    for i in range(pushed.shape[0]):
        count += pushed[i]
    if share == 0.0 or count == 0:
        return False
    dvx = push[PUSH_X] * share / (count * m)
    dvy = push[PUSH_Y] * share / (count * m)
    for i in range(pushed.shape[0]):
        if pushed[i]:
            v[i, 0] += dvx
            v[i, 1] += dvy
    return True
