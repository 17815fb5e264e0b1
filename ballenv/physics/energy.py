"""Energy (J) of a ring: kinetic, stretching, bending, gas (the gas-law potential), gravity.

Used by ``Trajectory.energy()`` and by the stepper's energy guard; ``Model.rest_energy`` is the
value of the same sum (without gravity) on the ring's inflated circle at rest.
"""

import math

from numba import njit

from .elastic import bend_energy, stretch_energy
from .loads import centre_of_mass, gas_energy, gravity_energy, polygon_area

ENERGY_KINETIC = 0
ENERGY_STRETCHING = 1
ENERGY_BENDING = 2
ENERGY_GAS = 3
ENERGY_GRAVITY = 4
ENERGY_PARTS = ("kinetic", "stretching", "bending", "gas", "gravity")


@njit(cache=True)
def ring_energy(model, r, x, v, parts):
    """Energy (J) of ring ``r`` by part into ``parts`` (5,), in the order of ``ENERGY_PARTS``;
    returns their sum."""
    m = model.node_mass[r]
    kinetic = 0.0
    for i in range(x.shape[0]):
        kinetic += v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1]
    parts[ENERGY_KINETIC] = 0.5 * m * kinetic
    parts[ENERGY_STRETCHING] = stretch_energy(x, model.rest_len[r], model.ea[r])
    parts[ENERGY_BENDING] = bend_energy(x, model.rest_len[r], model.ei[r], model.rest_turn[r])
    parts[ENERGY_GAS] = 0.0
    if model.pressurised[r]:
        parts[ENERGY_GAS] = gas_energy(
            polygon_area(x), model.gas_constant[r], model.gas_exponent, model.atmospheric_pressure,
            model.width[r],
        )  # fmt: skip
    parts[ENERGY_GRAVITY] = gravity_energy(x, m, model.gravity) if model.use_gravity else 0.0
    return parts.sum()


@njit(cache=True)
def remove_internal_kinetic_energy(x, v, m, excess):
    """Lower the kinetic energy of a ring (nodes ``x`` (N, 2) m, velocities ``v`` (N, 2) m/s, equal
    node masses ``m`` kg) by ``excess`` (J) without changing its momentum: the velocities relative
    to the mean ``V`` are scaled, ``v_i <- V + s (v_i - V)`` with ``s = sqrt(1 - excess / K_int)`` and
    ``K_int = m/2 sum |v_i - V|^2`` the kinetic energy of spin and deformation. This is the
    smallest change of ``v`` (in the mass norm) that removes ``excess`` and keeps the momentum; it
    lowers the angular momentum about the centre of mass by the factor ``s`` (a velocity
    post-process like Su, Sheth & Fedkiw's energy clamp, IEEE TVCG 2013). Returns False, leaving
    ``v`` untouched, if ``K_int <= excess``.
    """
    n = v.shape[0]
    _, _, vx, vy = centre_of_mass(x, v)
    internal = 0.0
    for i in range(n):
        internal += (v[i, 0] - vx) ** 2 + (v[i, 1] - vy) ** 2
    internal *= 0.5 * m
    if not internal > excess:
        return False
    keep = math.sqrt(1.0 - excess / internal)
    for i in range(n):
        v[i, 0] = vx + keep * (v[i, 0] - vx)
        v[i, 1] = vy + keep * (v[i, 1] - vy)
    return True
