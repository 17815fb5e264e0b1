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
from .contact import FREE, frame
from .effects.gas import gas_energy
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
    RAMP_REST_END,
    RAMP_REST_START,
    RAMP_SLOPE_END,
    RAMP_SLOPE_START,
    RAMP_T_END,
    RAMP_T_START,
)
from .ring import inflation_ratio_of


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
    """How far (0 to 1) the gas ramp ``ramp`` (a ``layout.RAMP`` row) is at time ``t`` (s): 1 from
    its end on."""
    if t >= ramp[RAMP_T_END]:
        return 1.0
    return max(0.0, (t - ramp[RAMP_T_START]) / (ramp[RAMP_T_END] - ramp[RAMP_T_START]))


@kernel(inline="always")
def ramp_rest_energy(ramp, s):
    """``(E_rest, dE_rest/dC)`` at fraction ``s`` of the gas ramp ``ramp``: the cubic Hermite
    interpolant in the amount of the rest energies and their slopes (:func:`rest_slope`) at its
    ends, exact at both. Its error is fourth order in the amount's change: 1e-5 J (2e-8 of the
    rest energy) for the env's 4 kPa steps, a thousandth of the energy guard's tolerance on a
    ball with 0.3 J of free energy; 0.07 J for a ramp from 10 to 50 kPa (2.2 times the amount).
    Inside a ramp the rest energy only scales that tolerance; at its end it is exact."""
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
    """Start a gas ramp of ring ``r`` (in ``drive``; :mod:`.drive` steps it): from the amount it
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
    ``[t_start, t_end]`` (s), shared equally by ``nodes[:count]`` (in ``drive``; :mod:`.drive`
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
