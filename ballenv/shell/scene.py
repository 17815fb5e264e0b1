"""What to simulate, validated on construction (SI units): ``Shell`` (one inflated ball), ``Ground``
(a half-space, fixed or moving), ``Drum`` (a turning cylinder the shells stay inside or outside) and
``Scene`` (shells, grounds, drums, effects and the numerical method).

Every field is checked when the object is made; a bad value raises ``ValueError`` naming the field,
the value and the valid range, e.g.::

    ValueError: Shell.thickness = 0.2 is out of range: must be a finite number in (0, 0.06] m
"""

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from numbers import Real
from typing import Any

from ..physics.scene import check_choice, check_int, check_real, check_sequence, fail

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


@dataclass(frozen=True)
class Ground:
    """A ground: the half-space ``n . x >= d(t)`` of any orientation, fixed or moving rigidly.

    Its plane moves with a constant velocity u plus an oscillation along its normal n, so that its
    offset along n (m) and its surface's velocity (m/s) are (as the ring's grounds,
    ``ballenv.physics.ground.motion``)::

        d(t) = height + (n . u) t + A sin(2 pi f t),     w(t) = u + A 2 pi f cos(2 pi f t) n

    (touch/motion.py). A vertex's barrier is taken against the plane at the end of each step, and
    Coulomb friction acts on its slip relative to the surface (a conveyor belt drags a ball along);
    the work the moving plane does is credited to the shell's energy budget (step/budget.py).

    normal: the unit normal n into the free side (any non-zero 3-vector, normalised here);
    height: the plane's offset d(0) (m) along n at t = 0 (the plane is ``n . x = height``);
    friction: the Coulomb coefficient mu in [0, 10] (0: frictionless); velocity: u (m/s), each
    component in [-1000, 1000] (its part along the plane: a conveyor belt; along n: a rising or
    sinking plate); amplitude: A (m) in [0, 100] of the oscillation along n (0: none); frequency:
    f (Hz) in [0, 1e5], above 0 when ``amplitude`` is (a vibrating table: peak acceleration
    ``A (2 pi f)^2`` m/s^2).
    """

    normal: tuple[float, float, float] = (0.0, 0.0, 1.0)
    height: float = 0.0
    friction: float = 0.0
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    amplitude: float = 0.0
    frequency: float = 0.0

    def __post_init__(self) -> None:
        o, s = "Ground", object.__setattr__
        n = check_vector3(o, "normal", self.normal, 1e6, "(not all zero)")
        length = math.sqrt(sum(c * c for c in n))
        if not length > 1e-12:
            fail(o, "normal", self.normal, "a non-zero 3-vector")
        s(self, "normal", (n[0] / length, n[1] / length, n[2] / length))
        s(self, "height", check_real(o, "height", self.height, -1e6, 1e6, "m"))
        s(self, "friction", check_real(o, "friction", self.friction, 0.0, 10.0))
        s(self, "velocity", check_vector3(o, "velocity", self.velocity, 1e3, "m/s"))
        s(self, "amplitude", check_real(o, "amplitude", self.amplitude, 0.0, 100.0, "m"))
        oscillates = self.amplitude > 0.0
        unit = "Hz (above 0 when amplitude > 0)" if oscillates else "Hz"
        s(self, "frequency", check_real(o, "frequency", self.frequency, 0.0, 1e5, unit, low_open=oscillates))

    @property
    def moves(self) -> bool:
        """The plane moves: a velocity or an oscillation."""
        return self.velocity != (0.0, 0.0, 0.0) or self.amplitude > 0.0


@dataclass(frozen=True)
class Drum:
    """A drum: an infinitely long circular cylinder of radius R about the line through ``centre`` c
    along the unit ``axis`` a, which the shells stay inside (``R - rho >= 0``) or outside
    (``rho - R >= 0``), ``rho = |(I - a a^T)(x - c)|`` (m) a point's distance from the axis.

    It turns about its axis at the angular velocity (rad/s, right-handed about a)::

        Omega(t) = Omega_0 min(1, t / T)          (T = 0: Omega_0 from the start)

    (the ring's drums, ``ballenv.physics.ground.motion``), its surface moving with
    ``w(x, t) = Omega(t) a x (x - c)`` (m/s), along the surface: the geometry never changes. A vertex
    is held off it by the grounds' barrier on its distance ``R - rho`` or ``rho - R`` (touch/drum.py),
    Coulomb friction acts on its slip relative to the surface (touch/drum_friction.py), and the
    work the turning drum does through friction is credited to the shell's energy budget
    (step/budget.py).

    radius: R (m) in (0, 1e6]; centre: c (m), each component in [-1e6, 1e6]; axis: a (any non-zero
    3-vector, normalised here); inside: True (default): the shells are inside the drum, False:
    outside it (a round obstacle); friction: the Coulomb coefficient mu in [0, 10] (0:
    frictionless); angular_velocity: Omega_0 (rad/s) in [-1e4, 1e4] (0: a fixed drum); spin_up: T
    (s) in [0, 1e6] over which Omega grows linearly from 0 to Omega_0 (0: none).
    """

    radius: float = 1.0
    centre: tuple[float, float, float] = (0.0, 0.0, 0.0)
    axis: tuple[float, float, float] = (0.0, 1.0, 0.0)
    inside: bool = True
    friction: float = 0.0
    angular_velocity: float = 0.0
    spin_up: float = 0.0

    def __post_init__(self) -> None:
        o, s = "Drum", object.__setattr__
        s(self, "radius", check_real(o, "radius", self.radius, 0.0, 1e6, "m", low_open=True))
        s(self, "centre", check_vector3(o, "centre", self.centre, 1e6, "m"))
        a = check_vector3(o, "axis", self.axis, 1e6, "(not all zero)")
        length = math.sqrt(sum(c * c for c in a))
        if not length > 1e-12:
            fail(o, "axis", self.axis, "a non-zero 3-vector")
        s(self, "axis", (a[0] / length, a[1] / length, a[2] / length))
        if not isinstance(self.inside, bool):
            fail(o, "inside", self.inside, "True or False")
        s(self, "friction", check_real(o, "friction", self.friction, 0.0, 10.0))
        spin = check_real(o, "angular_velocity", self.angular_velocity, -1e4, 1e4, "rad/s")
        s(self, "angular_velocity", spin)
        s(self, "spin_up", check_real(o, "spin_up", self.spin_up, 0.0, 1e6, "s"))

    @property
    def moves(self) -> bool:
        """The drum turns."""
        return self.angular_velocity != 0.0


INTEGRATORS = ("generalized_alpha", "backward_euler")


@dataclass(frozen=True)
class Scene:
    """Shells, grounds, the effects acting on them and the numerical method (SI units).

    shells: one or more :class:`Shell` (kept apart by a contact barrier); grounds: any number of
    :class:`Ground` half-spaces (fixed, or moving: a rising plate, a conveyor belt, a vibrating
    table); drums: any number of :class:`Drum` cylinders (default none) the shells stay inside or
    outside, fixed or turning about their axes. gravity: g (m/s^2) along -z in [0, 1000], or a
    3-vector (m/s^2).
    damping: c (1/s) in [0, 1e6] of the deformation damping ``F_i = -c m_i (v_i - v_rigid,i)``,
    ``v_rigid`` the mass-weighted least-squares rigid motion (translation plus spin about the
    centre of mass) of the shell's velocities: flight, spin and rolling are not damped.
    integrator: "generalized_alpha" (second order, default) or "backward_euler" (first order);
    rho_infinity: generalized-alpha's spectral radius at infinite frequency in [0, 1] (1: the
    trapezoidal rule, no numerical damping). dt: the largest (and first) step (s) in (0, 1];
    dt_min: the smallest before ``simulate`` gives up, in (0, dt]. adaptive: the step follows the
    local error estimate (at most ``rtol R`` m, RMS over the vertices, ``R`` the shell's radius);
    False: fixed steps ``dt``, halved only on rejection. rtol in (0, 1]. gas_exponent gamma in
    [0, 3] and atmospheric_pressure (Pa) in [0, 1e8] of the gas law. contact_distance: the
    barrier's reach dhat (m) in (0, 1]; contact_stiffness: its kappa (N/m) in (0, 1e12], None:
    each shell's ``E h``; friction_velocity: the slip speed eps_v (m/s) in (0, 10] below which
    Coulomb friction is smoothed (sticking). newton_tol in [1e-14, 1e-2]: Newton stops when every
    vertex's residual acceleration is below ``newton_tol (|g| + R / h^2)``; newton_max_iter in
    [1, 200]: more and the step is rejected. self_contact: True or False (default), the barrier
    also between a vertex and the triangles of its own shell that do not hold it (the same dhat m
    and kappa N/m; meant for meshes whose edges are longer than dhat).
    """

    shells: Sequence[Shell] = field(default_factory=lambda: (Shell(),))
    grounds: Sequence[Ground] = ()
    gravity: float | tuple[float, float, float] = 9.81
    damping: float = 0.0
    integrator: str = "generalized_alpha"
    rho_infinity: float = 0.9
    dt: float = 2e-3
    dt_min: float = 1e-8
    adaptive: bool = True
    rtol: float = 1e-4
    gas_exponent: float = 1.0
    atmospheric_pressure: float = ATMOSPHERIC_PRESSURE
    contact_distance: float = 1e-3
    contact_stiffness: float | None = None
    friction_velocity: float = 1e-3
    newton_tol: float = 1e-9
    newton_max_iter: int = 30
    self_contact: bool = False
    drums: Sequence[Drum] = ()

    def __post_init__(self) -> None:
        o, s = "Scene", object.__setattr__
        s(self, "shells", check_sequence(o, "shells", self.shells, Shell, allow_empty=False))
        s(self, "grounds", check_sequence(o, "grounds", self.grounds, Ground, allow_empty=True))
        if isinstance(self.gravity, Real) and not isinstance(self.gravity, bool):
            s(self, "gravity", check_real(o, "gravity", self.gravity, 0.0, 1000.0, "m/s^2"))
        else:
            s(self, "gravity", check_vector3(o, "gravity", self.gravity, 1000.0, "m/s^2"))
        s(self, "damping", check_real(o, "damping", self.damping, 0.0, 1e6, "1/s"))
        s(self, "integrator", check_choice(o, "integrator", self.integrator, INTEGRATORS))
        s(self, "rho_infinity", check_real(o, "rho_infinity", self.rho_infinity, 0.0, 1.0))
        s(self, "dt", check_real(o, "dt", self.dt, 0.0, 1.0, "s", low_open=True))
        s(self, "dt_min", check_real(o, "dt_min", self.dt_min, 0.0, self.dt, "s", low_open=True))
        if not isinstance(self.adaptive, bool):
            fail(o, "adaptive", self.adaptive, "True or False")
        s(self, "rtol", check_real(o, "rtol", self.rtol, 0.0, 1.0, low_open=True))
        s(self, "gas_exponent", check_real(o, "gas_exponent", self.gas_exponent, 0.0, 3.0))
        atm = check_real(o, "atmospheric_pressure", self.atmospheric_pressure, 0.0, 1e8, "Pa")
        s(self, "atmospheric_pressure", atm)
        s(
            self,
            "contact_distance",
            check_real(o, "contact_distance", self.contact_distance, 0.0, 1.0, "m", True),
        )
        if self.contact_stiffness is not None:
            kappa = check_real(o, "contact_stiffness", self.contact_stiffness, 0.0, 1e12, "N/m", True)
            s(self, "contact_stiffness", kappa)
        s(
            self,
            "friction_velocity",
            check_real(o, "friction_velocity", self.friction_velocity, 0.0, 10.0, "m/s", True),
        )
        s(self, "newton_tol", check_real(o, "newton_tol", self.newton_tol, 1e-14, 1e-2))
        s(self, "newton_max_iter", check_int(o, "newton_max_iter", self.newton_max_iter, 1, 200))
        s(self, "drums", check_sequence(o, "drums", self.drums, Drum, allow_empty=True))
        if not isinstance(self.self_contact, bool):
            fail(o, "self_contact", self.self_contact, "True or False")
        for k, shell in enumerate(self.shells):
            if shell.pressure + atm <= 0.0:
                fail(o, f"shells[{k}].pressure", shell.pressure, f"above -atmospheric_pressure ({atm:g} Pa)")

    @property
    def gravity_vector(self) -> tuple[float, float, float]:
        """Gravity's acceleration (m/s^2) as a 3-vector."""
        g = self.gravity
        return (0.0, 0.0, -float(g)) if isinstance(g, float) else g
