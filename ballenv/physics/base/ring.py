"""Geometry and material of one ring -> rest lengths, node masses, stiffnesses, initial nodes.

A ring of ``N`` nodes on a circle of radius ``R`` (m): a regular polygon, stress-free. Wall thickness
``h`` (m), out-of-plane width ``b`` (m), Young's modulus ``E`` (Pa), density ``rho`` (kg/m^3)::

    l0   = 2 R sin(pi / N)         rest edge length (m)
    phi0 = 2 pi / N                rest turning angle at each node (rad)
    EA   = E b h                   stretching stiffness (N)
    EI   = E b h^3 / 12            bending stiffness (N m^2)
    m    = rho b h l0              node mass (kg): the polygon's length shared equally
    A0   = N R^2 sin(2 pi / N) / 2 rest area of the polygon (m^2)

With this mass the discrete ring's breathing mode has exactly the continuum frequency
``sqrt(E / rho) / R`` for any ``N``.

A pressurised ring starts inflated: a regular polygon of radius ``r`` at which the hoop tension of
the stretched wall balances the gauge pressure ``p`` it holds (``Ring.pressure``, what a gauge on the
ball at rest reads). Per node, ``2 EA eps sin(pi/N) = p b r sin(2 pi/N)`` with ``eps = r / R - 1``::

    EA (r / R - 1) = p b r cos(pi / N)   =>   r = R / (1 - q),   q = p b R cos(pi / N) / EA

(the hoop tension ``T = p b r`` of a thin pressurised ring, up to the polygon's ``cos(pi/N)``); ``q``
must stay below 1 (beyond, no wall tension can hold the gas). A negative gauge pressure (an
under-inflated ball, a ring under external pressure) gives ``q < 0``: the wall is compressed to
``r < R`` by the hoop compression ``|p| b r``.
"""

import math
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from .jit import kernel


class RingLike(Protocol):
    """What these functions read of a ring (:class:`ballenv.physics.Ring` is one), in SI units."""

    @property
    def radius(self) -> float: ...  # m

    @property
    def n_nodes(self) -> int: ...

    @property
    def youngs_modulus(self) -> float: ...  # Pa

    @property
    def thickness(self) -> float: ...  # m

    @property
    def width(self) -> float: ...  # m

    @property
    def density(self) -> float: ...  # kg/m^3

    @property
    def pressure(self) -> float | None: ...  # Pa gauge

    @property
    def position(self) -> tuple[float, float]: ...  # m

    @property
    def velocity(self) -> tuple[float, float]: ...  # m/s

    @property
    def angular_velocity(self) -> float: ...  # rad/s


def rest_edge_length(radius: float, n_nodes: int) -> float:
    """``l0 = 2 R sin(pi / N)`` (m)."""
    return 2.0 * radius * math.sin(math.pi / n_nodes)


def rest_turning_angle(n_nodes: int) -> float:
    """``phi0 = 2 pi / N`` (rad)."""
    return 2.0 * math.pi / n_nodes


def rest_area(radius: float, n_nodes: int) -> float:
    """Area of the regular N-gon inscribed in the circle (m^2)."""
    return 0.5 * n_nodes * radius**2 * math.sin(2.0 * math.pi / n_nodes)


def stretching_stiffness(ring: RingLike) -> float:
    """``EA = E b h`` (N)."""
    return ring.youngs_modulus * ring.width * ring.thickness


def bending_stiffness(ring: RingLike) -> float:
    """``EI = E b h^3 / 12`` (N m^2)."""
    return ring.youngs_modulus * ring.width * ring.thickness**3 / 12.0


def node_mass(ring: RingLike) -> float:
    """``m = rho b h l0`` (kg)."""
    return ring.density * ring.width * ring.thickness * rest_edge_length(ring.radius, ring.n_nodes)


def total_mass(ring: RingLike) -> float:
    """Mass of the whole ring (kg)."""
    return ring.n_nodes * node_mass(ring)


def burst_pressure(radius: float, n_nodes: int, youngs_modulus: float, thickness: float) -> float:
    """The largest gauge pressure (Pa) a ring holds at rest: ``E h / (2 R cos(pi / N))``, where
    ``q = 1/2`` and the inflated wall is stretched by 100 % (``q / (1 - q)``); ``Ring.pressure``'s
    upper bound."""
    return 0.5 * youngs_modulus * thickness / (radius * math.cos(math.pi / n_nodes))


def crush_pressure(radius: float, n_nodes: int, youngs_modulus: float, thickness: float) -> float:
    """The most negative gauge pressure (Pa) a ring may hold at rest: ``-E h / (R cos(pi / N))``,
    where ``q = -1`` and the wall is compressed by 50 % (``r = R / 2``); ``Ring.pressure``'s lower
    bound (the scene's atmosphere bounds it too: the absolute pressure stays positive)."""
    return -2.0 * burst_pressure(radius, n_nodes, youngs_modulus, thickness)


@kernel
def inflation_ratio_of(pressure, width, radius, n_nodes, ea):
    """``q = p b R cos(pi / N) / EA`` (dimensionless) for gauge pressure ``p`` (Pa)."""
    return pressure * width * radius * math.cos(math.pi / n_nodes) / ea


def inflation_ratio(ring: RingLike) -> float:
    """``q`` of ``ring`` (see :func:`inflation_ratio_of`); 0 without gas. The inflated strain is
    q / (1 - q)."""
    if not ring.pressure:
        return 0.0
    return inflation_ratio_of(
        ring.pressure, ring.width, ring.radius, ring.n_nodes, stretching_stiffness(ring)
    )


def inflated_radius(ring: RingLike) -> float:
    """Radius (m) of the ring's inflated equilibrium circle, ``R / (1 - q)``; ``R`` without gas."""
    return ring.radius / (1.0 - inflation_ratio(ring))


def initial_nodes(ring: RingLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Node positions (N, 2) m and velocities (N, 2) m/s: the inflated circle in rigid motion."""
    theta = 2.0 * np.pi * np.arange(ring.n_nodes) / ring.n_nodes
    offset = inflated_radius(ring) * np.stack([np.cos(theta), np.sin(theta)], axis=1)
    x = offset + np.asarray(ring.position, dtype=float)
    v = np.empty_like(x)
    v[:, 0] = ring.velocity[0] - ring.angular_velocity * offset[:, 1]
    v[:, 1] = ring.velocity[1] + ring.angular_velocity * offset[:, 0]
    return x, v
