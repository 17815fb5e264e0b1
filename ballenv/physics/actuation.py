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
from .layout import ENERGY_BUDGET, ENERGY_TOTAL
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
