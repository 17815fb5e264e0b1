"""Actuation between steps: the amount of gas in a ring, and impulses on its nodes.

Both change a ring's energy on purpose, so each recomputes the energy the stepper carries for the
ring (its energy and free energy for the energy guard, which then compares only steps without
actuation; its energy budget, raised or lowered by the change: :func:`recount_energy`). Both keep
the integrator's carried acceleration: an actuation is a change of load or velocity between steps,
which the integrator steps through like any other. (Setting ``a = F / m`` there, as at the start of
a run, restarted generalized-alpha from a state off its equilibrium at every control step; its
first step at a large ``omega h`` overshoots, and with random gas commands the energy guard rejected
1.4 steps per control step.) :func:`restart` is the start of a run: energy and ``a = F / m``.

* :func:`set_rest_pressure`: the gas is set to the amount whose gauge pressure on the ring's inflated
  circle at rest is ``p`` (Pa), i.e. ``(p + p_atm) A_r^k`` with ``A_r`` the area of that circle
  (radius ``R / (1 - q)``, :mod:`ballenv.physics.base.ring`). The gas law then sets the pressure as the ring
  deforms:
  raising ``p`` while the ball is squashed does work ``int p dA`` on the ring as it re-expands.
* :func:`apply_impulse`: a momentum ``J`` (N s) shared equally by chosen nodes (equal masses), so
  the ring's momentum changes by exactly ``J``.

**Actuation spread over time, delivered step by step: gas ramps and spread impulses.**

Actuation at one instant (:func:`set_rest_pressure`, :func:`apply_impulse`) changes a
ring between steps at once: a staircase of gas amounts at a controller's rate rings the ring's
breathing mode, and a paddle's whole strike lands in one instant. A :class:`model.Drive` spreads
them over time (started by :func:`step.actuation.ramp_rest_pressure` and
:func:`step.actuation.spread_impulse`). ``step.stepper.advance`` takes the drive as its own argument and,
unless it is None (then numba prunes these calls and compiles none of this module), calls two
phases:

* :func:`drive_landing`: steps land on the start and end of every ramp and push window, as they
  land on output times (the step is shortened, its size control is not);
* :func:`drive_step`, before every trial step from ``t`` to ``t + h``, actuates the start state:

  - *gas ramp*: the ring holds the amount of the ramp at the step's force-evaluation time
    ``t_f = t + h - alpha_f h`` (:func:`step.integrator.force_time`), linear in time,
    ``C(t_f) = C_0 + (t_f - t_0) / (t_1 - t_0) (C_1 - C_0)``: the end of the step for backward
    Euler, and for generalized-alpha the time it evaluates every load at (``F`` at
    ``t_{n+1-alpha_f}``, as Chung & Hulbert take a time-dependent load), so the ramp is stepped to
    the integrator's own order. Once the ramp has ended (``t >= t_1``; the stepper also calls
    this phase with ``h = 0`` after each accepted step), the ring holds the ramp's end amount
    exactly, so from the end of a ramp on the amount is its setpoint to the bit (for
    generalized-alpha the last step held that of ``t_1 - alpha_f h``). The rest energy
    (``Model.rest_energy``) follows the amount (:func:`step.actuation.ramp_rest_energy`);
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

  then recounts the ring's carried energy (:func:`step.actuation.recount_energy`): its energy budget is
  credited with ``E(x, v + dv; C_new) - E(x, v; C_old)`` at the start state, the pump's and the
  push's work. A trial step that is rejected leaves its actuation in place; the retry actuates
  again from there, so the credits telescope to those of the accepted steps.

Why the credit is the work done: the ring's energy (:func:`step.energy_budget.free_energy`) changes only
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

from ..base.geometry import polygon_area
from ..base.jit import kernel
from ..base.layout import (
    ENERGY_BUDGET,
    ENERGY_TOTAL,
    PUSH_DELIVERED,
    PUSH_T_END,
    PUSH_T_START,
    PUSH_X,
    PUSH_Y,
    RAMP_AMOUNT_END,
    RAMP_AMOUNT_START,
    RAMP_REST_END,
    RAMP_REST_START,
    RAMP_SLOPE_END,
    RAMP_SLOPE_START,
    RAMP_T_END,
    RAMP_T_START,
)
from ..base.ring import inflation_ratio_of
from ..effects.assembly import gravity_column, ring_energy, ring_force
from ..effects.gas import gas_energy
from ..ground.contact import FREE, frame
from .energy_budget import free_energy
from .integrator import force_time, time_tolerance


@kernel
def rest_circle_radius(model, r, pressure, n_nodes):
    """Radius (m) of ring ``r``'s inflated circle at rest for gauge pressure ``pressure`` (Pa)."""
    q = inflation_ratio_of(pressure, model.width[r], model.radius[r], n_nodes, model.ea[r])
    return model.radius[r] / (1.0 - q)


@kernel
def set_rest_pressure(model, r, pressure, x, v, energy, ws):
    """Set ring ``r``'s gas to the amount with gauge pressure ``pressure`` (Pa) at rest
    (:func:`set_gas`), then recount its carried ``energy`` (columns ``base.layout.ENERGY``;
    :func:`recount_energy`) for state ``x, v``."""
    set_gas(model, r, pressure, x.shape[0], ws)
    recount_energy(model, r, x, v, energy, ws)


@kernel
def set_gas(model, r, pressure, n, ws):
    """The gas amount of ring ``r`` (``n`` nodes) whose gauge pressure on its inflated circle at rest
    is ``pressure`` (Pa) (see module doc): updates ``model.gas_constant[r]`` and
    ``model.rest_energy[r]`` only. ``ws.xe``/``ws.ve`` are used as scratch."""
    radius = rest_circle_radius(model, r, pressure, n)
    circle = ws.xe
    still = ws.ve
    for i in range(n):
        theta = 2.0 * math.pi * i / n
        circle[i, 0] = radius * math.cos(theta)
        circle[i, 1] = radius * math.sin(theta)
        still[i, 0] = 0.0
        still[i, 1] = 0.0
    area = polygon_area(circle)
    model.gas_constant[r] = (pressure + model.atmospheric_pressure) * area**model.gas_exponent
    total = ring_energy(model, r, circle, still, ws.energy)
    g = gravity_column(model)
    model.rest_energy[r] = total - (ws.energy[g] if g >= 0 else 0.0)


@kernel
def apply_impulse(model, r, x, v, energy, ws, nodes, count, jx, jy):
    """Add momentum ``(jx, jy)`` (N s) to ring ``r``, shared equally by ``nodes[:count]``, and
    recount its carried ``energy`` (:func:`recount_energy`)."""
    if count == 0:
        return
    dvx = jx / (count * model.node_mass[r])
    dvy = jy / (count * model.node_mass[r])
    for k in range(count):
        i = nodes[k]
        v[i, 0] += dvx
        v[i, 1] += dvy
    recount_energy(model, r, x, v, energy, ws)


@kernel(inline="always")
def recount_energy(model, r, x, v, energy, ws):
    """Recompute ring ``r``'s carried energy (columns ``base.layout.ENERGY``) after an actuation; the
    change of energy is added to the ring's energy budget."""
    before = energy[ENERGY_TOTAL]
    free_energy(model, r, x, v, ws, energy)
    energy[ENERGY_BUDGET] += energy[ENERGY_TOTAL] - before


@kernel
def restart(model, r, x, v, a, active, energy, ws):
    """Start ring ``r`` afresh from ``x, v``: its carried energy (:func:`recount_energy`) and start
    acceleration ``a = F / m`` (normal part zeroed on ground-constrained nodes, which rest on the
    surface)."""
    recount_energy(model, r, x, v, energy, ws)
    ring_force(model, r, x, v, ws.force)
    m = model.node_mass[r]
    for i in range(x.shape[0]):
        ax = ws.force[i, 0] / m
        ay = ws.force[i, 1] / m
        g = active[i]
        if g != FREE:
            nx, ny, _ = frame(model.grounds, g, x[i, 0], x[i, 1])
            an = ax * nx + ay * ny
            ax -= an * nx
            ay -= an * ny
        a[i, 0] = ax
        a[i, 1] = ay


@kernel(inline="always")
def rest_slope(model, r, pressure, n):
    """``d E_rest / dC`` (J per Pa m^(2k)): how ring ``r``'s rest energy (``Model.rest_energy``)
    changes with its gas amount ``C``, at the amount whose gauge pressure at rest is ``pressure``
    (Pa). The inflated circle is the equilibrium of the energy at a fixed amount, so only the
    amount's own term moves it (the envelope theorem): ``dU/dC = -b phi(A)`` at the circle's area
    ``A = n/2 sin(2 pi / n) r^2`` (:func:`effects.gas.gas_energy` with ``C = 1``, ``p_atm = 0``)."""
    radius = rest_circle_radius(model, r, pressure, n)
    area = 0.5 * n * math.sin(2.0 * math.pi / n) * radius * radius
    return gas_energy(area, 1.0, model.gas_exponent, 0.0, model.width[r])


@kernel(inline="always")
def ramp_fraction(ramp, t):
    """How far (0 to 1) the gas ramp ``ramp`` (a ``base.layout.RAMP`` row) is at time ``t`` (s): 1 from
    its end on."""
    if t >= ramp[RAMP_T_END]:
        return 1.0
    return max(0.0, (t - ramp[RAMP_T_START]) / (ramp[RAMP_T_END] - ramp[RAMP_T_START]))


@kernel(inline="always")
def ramp_rest_energy(ramp, s):
    """``(E_rest, dE_rest/dC)`` at fraction ``s`` of the gas ramp ``ramp``: the cubic Hermite
    interpolant in the amount of the rest energies and their slopes (:func:`rest_slope`) at its
    ends, exact at both; its error is fourth order in the amount's change. Inside a ramp the rest
    energy only scales the energy guard's tolerance; at its end it is exact."""
    change = ramp[RAMP_AMOUNT_END] - ramp[RAMP_AMOUNT_START]
    e0, e1 = ramp[RAMP_REST_START], ramp[RAMP_REST_END]
    d0, d1 = change * ramp[RAMP_SLOPE_START], change * ramp[RAMP_SLOPE_END]
    s2 = s * s
    s3 = s2 * s
    energy = (2.0 * s3 - 3.0 * s2 + 1.0) * e0 + (s3 - 2.0 * s2 + s) * d0 + (3.0 * s2 - 2.0 * s3) * e1
    energy += (s3 - s2) * d1
    if change == 0.0:
        return energy, ramp[RAMP_SLOPE_START]
    slope = (6.0 * s2 - 6.0 * s) * (e0 - e1) + (3.0 * s2 - 4.0 * s + 1.0) * d0 + (3.0 * s2 - 2.0 * s) * d1
    return energy, slope / change


@kernel
def ramp_rest_pressure(model, drive, r, pressure, t_start, t_end, ws):
    """Start a gas ramp of ring ``r`` (in ``drive``; :func:`drive_step` steps it): from the amount it
    holds at ``t_start`` to the amount whose gauge pressure at rest is ``pressure`` (Pa) at
    ``t_end`` (s), linear in time. Nothing changes yet (each step takes the amount of its own time),
    so the carried energy stays as it is. Replaces a ramp under way."""
    ramp = drive.ramp[r]
    held, rest = model.gas_constant[r], model.rest_energy[r]
    slope = ramp[RAMP_SLOPE_END]
    if ramp[RAMP_T_END] > t_start:  # a ramp under way: its slope at the amount held
        change = ramp[RAMP_AMOUNT_END] - ramp[RAMP_AMOUNT_START]
        s = 1.0 if change == 0.0 else (held - ramp[RAMP_AMOUNT_START]) / change
        slope = ramp_rest_energy(ramp, s)[1]
    ramp[RAMP_AMOUNT_START], ramp[RAMP_REST_START], ramp[RAMP_SLOPE_START] = held, rest, slope
    n = drive.pushed.shape[1]
    set_gas(model, r, pressure, n, ws)  # the setpoint's amount and rest energy, for the ramp's end
    ramp[RAMP_AMOUNT_END], ramp[RAMP_REST_END] = model.gas_constant[r], model.rest_energy[r]
    ramp[RAMP_SLOPE_END] = rest_slope(model, r, pressure, n)
    model.gas_constant[r], model.rest_energy[r] = held, rest
    ramp[RAMP_T_START] = t_start
    ramp[RAMP_T_END] = t_end


@kernel
def hold_gas(model, drive, r, pressure, n):
    """Ring ``r`` (``n`` nodes) holds the gas amount :func:`set_gas` set for gauge pressure
    ``pressure`` (Pa) at rest, and no ramp moves it (its ramp in ``drive`` off, its end that
    amount, the start of the next ramp)."""
    ramp = drive.ramp[r]
    ramp[RAMP_T_END] = -math.inf
    ramp[RAMP_AMOUNT_END] = model.gas_constant[r]
    ramp[RAMP_REST_END] = model.rest_energy[r]
    ramp[RAMP_SLOPE_END] = rest_slope(model, r, pressure, n)


@kernel
def spread_impulse(drive, r, nodes, count, jx, jy, t_start, t_end):
    """Start delivering momentum ``(jx, jy)`` (N s) to ring ``r`` at a constant rate over
    ``[t_start, t_end]`` (s), shared equally by ``nodes[:count]`` (in ``drive``; :func:`drive_step`
    delivers it step by step). Replaces a push of the ring under way (what it delivered stays)."""
    push = drive.push[r]
    pushed = drive.pushed[r]
    for i in range(pushed.shape[0]):
        pushed[i] = False
    for k in range(count):
        pushed[nodes[k]] = True
    push[PUSH_T_START] = t_start
    push[PUSH_T_END] = t_end
    push[PUSH_X] = jx
    push[PUSH_Y] = jy
    push[PUSH_DELIVERED] = 0.0


@kernel
def stop_push(drive, r):
    """Ring ``r``'s spread impulse off (what it delivered stays)."""
    drive.push[r, PUSH_T_END] = -math.inf


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
    ``push`` (a ``base.layout.PUSH`` row) up to ``stop`` (s): ``J (f(stop) - f_done) / (count m)`` on
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
