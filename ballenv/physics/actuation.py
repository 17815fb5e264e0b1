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
  (radius ``R / (1 - q)``, :mod:`ring`). The gas law then sets the pressure as the ring deforms:
  raising ``p`` while the ball is squashed does work ``int p dA`` on the ring as it re-expands.
* :func:`apply_impulse`: a momentum ``J`` (N s) shared equally by chosen nodes (equal masses), so
  the ring's momentum changes by exactly ``J``.
"""

import math

from .assembly import gravity_column, ring_energy, ring_force
from .contact import FREE
from .energy import free_energy
from .geometry import polygon_area
from .jit import kernel
from .layout import (
    ENERGY_BUDGET,
    ENERGY_TOTAL,
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
from .ring import inflation_ratio_of

REST_PRESSURE_ITERATIONS = 32  # at most, of rest_pressure_of's Newton iteration


@kernel
def rest_circle_radius(model, r, pressure, n_nodes):
    """Radius (m) of ring ``r``'s inflated circle at rest for gauge pressure ``pressure`` (Pa)."""
    q = inflation_ratio_of(pressure, model.width[r], model.radius[r], n_nodes, model.ea[r])
    return model.radius[r] / (1.0 - q)


@kernel
def set_rest_pressure(model, r, pressure, x, v, energy, ws):
    """Set ring ``r``'s gas to the amount with gauge pressure ``pressure`` (Pa) at rest
    (:func:`set_gas`), then recount its carried ``energy`` (columns ``layout.ENERGY``;
    :func:`recount_energy`) for state ``x, v``."""
    set_gas(model, r, pressure, x.shape[0], ws)
    recount_energy(model, r, x, v, energy, ws)


@kernel
def set_gas(model, r, pressure, n, ws):
    """The gas amount of ring ``r`` (``n`` nodes) whose gauge pressure on its inflated circle at rest
    is ``pressure`` (Pa) (see module doc): updates ``model.gas_constant[r]`` and
    ``model.rest_energy[r]`` only. ``ws.xe``/``ws.ve`` are used as scratch."""
    model.gas_constant[r] = rest_amount(model, r, pressure, n, ws)
    model.rest_energy[r] = rest_circle_energy(model, r, ws)


@kernel
def set_gas_amount(model, r, amount, pressure, n, ws):
    """Ring ``r`` holds gas ``amount`` (Pa m^(2k)) whose gauge pressure at rest is ``pressure`` (Pa;
    :func:`rest_pressure_of`): updates ``model.gas_constant[r]`` and ``model.rest_energy[r]`` only.
    ``ws.xe``/``ws.ve`` are used as scratch."""
    rest_amount(model, r, pressure, n, ws)
    model.gas_constant[r] = amount
    model.rest_energy[r] = rest_circle_energy(model, r, ws)


@kernel
def rest_amount(model, r, pressure, n, ws):
    """The gas amount ``(p + p_atm) A^k`` (Pa m^(2k)) of ring ``r``'s inflated circle at rest for
    gauge pressure ``pressure`` (Pa), that circle's nodes left in ``ws.xe`` (``ws.ve`` zeroed)."""
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
    return (pressure + model.atmospheric_pressure) * area**model.gas_exponent


@kernel
def rest_circle_energy(model, r, ws):
    """Energy (J), gravity left out, of ring ``r`` at rest on the circle in ``ws.xe`` holding gas
    ``model.gas_constant[r]``: ``model.rest_energy[r]`` once that circle is its inflated one."""
    total = ring_energy(model, r, ws.xe, ws.ve, ws.energy)
    g = gravity_column(model)
    return total - (ws.energy[g] if g >= 0 else 0.0)


@kernel
def rest_pressure_of(model, r, amount, guess, n):
    """The gauge pressure ``p`` (Pa) at rest of gas ``amount`` ``C`` (Pa m^(2k)) in ring ``r`` (``n``
    nodes): the root of ``C(p) = (p + p_atm) A(p)^k`` with ``A(p) = n/2 sin(2 pi / n) r(p)^2`` the
    area of the inflated circle, ``r(p) = R / (1 - a p)``, ``a = q / p`` (:mod:`ring`), by Newton's
    iteration from ``guess`` (Pa): ``C`` grows with ``p`` and is convex, so the iteration converges
    from a guess near the root (a step past the burst pressure ``1 / a`` is halved back)."""
    a = inflation_ratio_of(1.0, model.width[r], model.radius[r], n, model.ea[r])
    kappa = 0.5 * n * math.sin(2.0 * math.pi / n)
    k = model.gas_exponent
    p = guess
    for _ in range(REST_PRESSURE_ITERATIONS):
        radius = model.radius[r] / (1.0 - a * p)
        area = kappa * radius * radius
        absolute = p + model.atmospheric_pressure
        slope = area**k * (1.0 + 2.0 * k * absolute * a / (1.0 - a * p))  # dC/dp, Pa m^(2k) / Pa
        step = (absolute * area**k - amount) / slope
        last = p
        p -= step
        if not a * p < 1.0:  # past the burst pressure (or not a number): halfway from the last to it
            p = 0.5 * (last + 1.0 / a)
        if abs(step) <= 1e-12 * (abs(p) + model.atmospheric_pressure) + 1e-9:
            break
    return p


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


@kernel
def recount_energy(model, r, x, v, energy, ws):
    """Recompute ring ``r``'s carried energy (columns ``layout.ENERGY``) after an actuation; the
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
            nx, ny = model.grounds[g, 0], model.grounds[g, 1]
            an = ax * nx + ay * ny
            ax -= an * nx
            ay -= an * ny
        a[i, 0] = ax
        a[i, 1] = ay


@kernel
def ramp_rest_pressure(model, r, pressure, t_start, t_end, ws):
    """Start a gas ramp of ring ``r`` (``model.drive``; :mod:`.drive` steps it): from the amount it
    holds at ``t_start`` to the amount whose gauge pressure at rest is ``pressure`` (Pa) at
    ``t_end`` (s), linear in time. Nothing changes yet (the stepper's steps set the amount of their
    own time), so the carried energy stays as it is."""
    ramp = model.drive.ramp[r]
    n = model.drive.pushed.shape[1]
    held = model.gas_constant[r]
    guess = ramp[RAMP_PRESSURE_END]
    if ramp[RAMP_T_END] > t_start:  # a ramp under way: start from its present point
        guess = ramp_value(ramp, RAMP_PRESSURE_START, RAMP_PRESSURE_END, t_start)
    ramp[RAMP_PRESSURE_START] = rest_pressure_of(model, r, held, guess, n)
    ramp[RAMP_AMOUNT_START] = held
    ramp[RAMP_AMOUNT_END] = rest_amount(model, r, pressure, n, ws)
    ramp[RAMP_PRESSURE_END] = pressure
    ramp[RAMP_T_START] = t_start
    ramp[RAMP_T_END] = t_end


@kernel
def hold_gas(drive, r, amount, pressure):
    """Ring ``r``'s gas ramp off: it holds ``amount`` (Pa m^(2k)), gauge pressure ``pressure`` (Pa)
    at rest (after :func:`set_gas`: no ramp may then move the amount set)."""
    ramp = drive.ramp[r]
    ramp[RAMP_T_END] = -math.inf
    ramp[RAMP_AMOUNT_END] = amount
    ramp[RAMP_PRESSURE_END] = pressure


@kernel
def ramp_value(ramp, start, end, t):
    """Column ``start``'s value moved linearly in time to column ``end``'s over the ramp ``ramp``
    (a ``layout.RAMP`` row), at time ``t`` (s); the end value exactly from the ramp's end on."""
    if t >= ramp[RAMP_T_END]:
        return ramp[end]
    s = max(0.0, (t - ramp[RAMP_T_START]) / (ramp[RAMP_T_END] - ramp[RAMP_T_START]))
    return ramp[start] + s * (ramp[end] - ramp[start])


@kernel
def spread_impulse(model, r, nodes, count, jx, jy, t_start, t_end):
    """Start delivering momentum ``(jx, jy)`` (N s) to ring ``r`` at a constant rate over
    ``[t_start, t_end]`` (s), shared equally by ``nodes[:count]`` (``model.drive``; :mod:`.drive`
    delivers it step by step). Replaces a push of the ring under way."""
    push = model.drive.push[r]
    pushed = model.drive.pushed[r]
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
