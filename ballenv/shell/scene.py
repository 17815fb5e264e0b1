"""The description of one inflated shell ball, validated on construction (SI units).

Every field is checked when the object is made; a bad value raises ``ValueError`` naming the field,
the value and the valid range, e.g.::

    ValueError: Shell.thickness = 0.2 is out of range: must be a finite number in (0, 0.06] m
"""

import math
from dataclasses import dataclass
from numbers import Real
from typing import Any

from ..physics.scene import check_int, check_real, fail

MAX_SUBDIVISIONS = 6  # 40962 vertices
ATMOSPHERIC_PRESSURE = 101325.0  # Pa


def check_vector3(owner: str, name: str, value: Any, bound: float, unit: str) -> tuple[float, float, float]:
    """Return ``value`` as a tuple of three finite floats with magnitude at most ``bound``."""
    valid = f"three finite numbers in [-{bound:g}, {bound:g}] {unit}"
    try:
        items = tuple(value)
    except TypeError:
        fail(owner, name, value, valid)
    if len(items) != 3:
        fail(owner, name, value, valid)
    out = []
    for item in items:
        if isinstance(item, bool) or not isinstance(item, Real) or not math.isfinite(float(item)):
            fail(owner, name, value, valid)
        if abs(float(item)) > bound:
            fail(owner, name, value, valid)
        out.append(float(item))
    return out[0], out[1], out[2]


@dataclass(frozen=True)
class Shell:
    """An inflated ball: a thin elastic skin, stress-free on a sphere, around a gas.

    radius: rest radius R (m) of the stress-free skin; subdivisions: k of the icosphere mesh
    (10 * 4**k + 2 vertices); youngs_modulus E (Pa), poisson_ratio nu, thickness h (m) and density
    rho (kg/m^3) of the skin; pressure: the gas's gauge pressure p (Pa) when the skin has its rest
    shape (it sets the amount of gas); position (m) of the centre, velocity (m/s) of the centre and
    angular_velocity (rad/s) about it.
    """

    radius: float = 0.12
    subdivisions: int = 2
    youngs_modulus: float = 5e6
    poisson_ratio: float = 0.45
    thickness: float = 3e-3
    density: float = 1100.0
    pressure: float = 55e3
    position: tuple[float, float, float] = (0.0, 0.0, 1.0)
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    angular_velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        real = {
            "radius": check_real("Shell", "radius", self.radius, 0.0, 100.0, "m", low_open=True),
            "youngs_modulus": check_real(
                "Shell", "youngs_modulus", self.youngs_modulus, 0.0, 1e12, "Pa", low_open=True
            ),
            "poisson_ratio": check_real("Shell", "poisson_ratio", self.poisson_ratio, 0.0, 0.5),
            "density": check_real("Shell", "density", self.density, 0.0, 1e5, "kg/m^3", low_open=True),
            "pressure": check_real("Shell", "pressure", self.pressure, -1e8, 1e8, "Pa (gauge)"),
        }
        real["thickness"] = check_real(
            "Shell", "thickness", self.thickness, 0.0, 0.5 * real["radius"], "m", low_open=True
        )
        for name, value in real.items():
            object.__setattr__(self, name, value)
        k = check_int("Shell", "subdivisions", self.subdivisions, 0, MAX_SUBDIVISIONS)
        object.__setattr__(self, "subdivisions", k)
        vectors = (("position", 1e6, "m"), ("velocity", 1e4, "m/s"), ("angular_velocity", 1e6, "rad/s"))
        for name, bound, unit in vectors:
            object.__setattr__(self, name, check_vector3("Shell", name, getattr(self, name), bound, unit))

    @property
    def n_vertices(self) -> int:
        """Vertices of the icosphere mesh: 10 * 4**k + 2."""
        return 10 * 4**self.subdivisions + 2

    @property
    def bending_stiffness(self) -> float:
        """Plate bending stiffness k_b = E h^3 / (12 (1 - nu^2)) (N m)."""
        nu = self.poisson_ratio
        return self.youngs_modulus * self.thickness**3 / (12.0 * (1.0 - nu * nu))
