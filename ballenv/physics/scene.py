"""Ring and Scene descriptions, validated on construction (SI units).

Every field is checked when the object is made; a bad value raises ``ValueError`` naming the field,
the value and the valid range, e.g.::

    ValueError: Ring.youngs_modulus = -1.0 is out of range: must be a finite number in (0, 1e+12] Pa
"""

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from numbers import Integral, Real
from typing import Any, NoReturn, TypeVar

from .base.ring import burst_pressure, crush_pressure

INTEGRATORS = ("backward_euler", "generalized_alpha")
DAMPING_MODES = ("rigid", "centre_of_mass")
CONTACT_METHODS = ("mass_modification", "predictor_corrector")
SELF_INTERSECTION = ("barrier", "reject", "ignore")
CONTACT_ERRORS = ("impulse", "doubling")
DEFAULT_RTOL = 1e-2  # the adaptive step's relative tolerance when a Scene names neither rtol nor impulse_tol

T = TypeVar("T")


def fail(owner: str, name: str, value: object, valid: str) -> NoReturn:
    """Raise the ValueError of parameter ``owner.name`` out of range: its value and ``valid``."""
    raise ValueError(f"{owner}.{name} = {value!r} is out of range: must be {valid}")


def check_real(
    owner: str,
    name: str,
    value: object,
    low: float,
    high: float,
    unit: str = "",
    low_open: bool = False,
    high_open: bool = False,
) -> float:
    """Return ``value`` as float if it is a finite real within the interval, else raise ValueError."""
    lo_br = "(" if low_open else "["
    hi_br = ")" if high_open else "]"
    valid = f"a finite number in {lo_br}{low:g}, {high:g}{hi_br}" + (f" {unit}" if unit else "")
    if isinstance(value, bool) or not isinstance(value, Real):
        fail(owner, name, value, valid)
    v = float(value)
    if not math.isfinite(v):
        fail(owner, name, value, valid)
    if v < low or v > high or (low_open and v == low) or (high_open and v == high):
        fail(owner, name, value, valid)
    return v


def check_int(owner: str, name: str, value: object, low: int, high: int) -> int:
    """Return ``value`` as int if it is an integer within [low, high], else raise ValueError."""
    if isinstance(value, bool) or not isinstance(value, Integral) or not low <= int(value) <= high:
        fail(owner, name, value, f"an integer in [{low}, {high}]")
    return int(value)


def check_vector(owner: str, name: str, value: Any, bound: float, unit: str) -> tuple[float, ...]:
    """Return ``value`` as a tuple of two finite floats with magnitude at most ``bound``."""
    valid = f"a pair of finite numbers in [-{bound:g}, {bound:g}] {unit}"
    try:
        items = tuple(value)
    except TypeError:
        fail(owner, name, value, valid)
    if len(items) != 2:
        fail(owner, name, value, valid)
    out = []
    for item in items:
        if isinstance(item, bool) or not isinstance(item, Real):
            fail(owner, name, value, valid)
        f = float(item)
        if not math.isfinite(f) or abs(f) > bound:
            fail(owner, name, value, valid)
        out.append(f)
    return tuple(out)


def check_sequence(owner: str, name: str, value: Any, cls: type[T], allow_empty: bool) -> tuple[T, ...]:
    """Return ``value`` (one ``cls`` or a sequence of them) as a tuple, else raise ValueError."""
    valid = f"a {'' if allow_empty else 'non-empty '}sequence of {cls.__name__}"
    items = (value,) if isinstance(value, cls) else value
    try:
        items = tuple(items)
    except TypeError:
        fail(owner, name, value, valid)
    if (not items and not allow_empty) or not all(isinstance(item, cls) for item in items):
        fail(owner, name, value, valid)
    return items


def check_gauge_pressure(
    owner: str, name: str, value: object, ring: "Ring", atmospheric_pressure: float | None = None
) -> float:
    """Return ``value`` (a gauge pressure at rest, Pa) as float if ``ring``'s wall holds it, else raise
    ValueError: at most ``min(1e8, burst_pressure)`` (the wall stretched by 100 %), at least
    ``max(-1e8, crush_pressure)`` (the wall compressed by 50 %); with ``atmospheric_pressure`` given,
    a negative value must also keep the absolute pressure ``p + p_atm`` positive (so none without
    an atmosphere)."""
    geometry = (ring.radius, ring.n_nodes, ring.youngs_modulus, ring.thickness)
    high = min(1e8, burst_pressure(*geometry))
    low = max(-1e8, crush_pressure(*geometry))
    unit = "Pa; the bounds compress the wall by 50 % and stretch it by 100 %"
    low_open = False
    if atmospheric_pressure is not None and -atmospheric_pressure >= low:
        low, low_open = (-atmospheric_pressure, True) if atmospheric_pressure > 0.0 else (0.0, False)
        unit = "Pa; the absolute pressure p + Scene.atmospheric_pressure must stay positive"
    return check_real(owner, name, value, low, high, unit, low_open=low_open)


def check_choice(owner: str, name: str, value: object, choices: Sequence[str]) -> str:
    """Return ``value`` if it is one of ``choices`` (strings), else raise ValueError."""
    if not isinstance(value, str) or value not in choices:
        fail(owner, name, value, "one of " + ", ".join(repr(c) for c in choices))
    return value


MIN_RADIUS = 1e-3  # m: the smallest ring (its wall modes outrun any allowed step below it)
MIN_DENSITY = 1.0  # kg/m^3: the lightest wall


@dataclass(frozen=True)
class Ring:
    """One inflated elastic ring (a 2-D ball).

    Attributes:
        radius: rest radius R of the centreline circle (m), in [1e-3, 100] (a millimetre and up: below, the
            wall's modes outrun any step the scene allows).
        n_nodes: number of nodes N, in [3, 4096].
        youngs_modulus: E of the wall (Pa), in (0, 1e12].
        thickness: wall thickness h (m), in (0, radius).
        width: out-of-plane width b (m), in (0, 100].
        density: wall density rho (kg/m^3), in [1, 1e5] (lighter than any solid wall stays out).
        pressure: gauge pressure (Pa) of the inflated ball at rest, in
            [max(-1e8, -E h / (R cos(pi/N))), min(1e8, E h / (2 R cos(pi/N)))] (the wall compressed by
            50 %, stretched by 100 %), or None for no gas at all. Negative: an under-inflated ball or
            a ring under external pressure; the scene then asks that the absolute pressure
            ``pressure + Scene.atmospheric_pressure`` be positive. The ring starts at the circle where
            its wall tension holds this pressure (radius ``R / (1 - p b R cos(pi/N) / EA)``); the amount
            of gas is fixed there and the gas law sets the pressure as the ring deforms (or, with
            ``Scene.gas_exponent`` 0, a regulator holds it).
        position: initial centre (m), each component in [-1e6, 1e6].
        velocity: initial centre velocity (m/s), each component in [-1000, 1000].
        angular_velocity: initial spin (rad/s, counter-clockwise), in [-1e5, 1e5].
    """

    radius: float = 0.1
    n_nodes: int = 64
    youngs_modulus: float = 10e6
    thickness: float = 2e-3
    width: float = 0.02
    density: float = 1100.0
    pressure: float | None = 30e3
    position: tuple[float, float] = (0.0, 1.0)
    velocity: tuple[float, float] = (0.0, 0.0)
    angular_velocity: float = 0.0

    def __post_init__(self) -> None:
        o = "Ring"
        s = object.__setattr__
        s(self, "radius", check_real(o, "radius", self.radius, MIN_RADIUS, 100.0, "m"))
        s(self, "n_nodes", check_int(o, "n_nodes", self.n_nodes, 3, 4096))
        s(
            self,
            "youngs_modulus",
            check_real(o, "youngs_modulus", self.youngs_modulus, 0.0, 1e12, "Pa", low_open=True),
        )
        s(
            self,
            "thickness",
            check_real(o, "thickness", self.thickness, 0.0, self.radius, "m (below radius)", True, True),
        )
        s(self, "width", check_real(o, "width", self.width, 0.0, 100.0, "m", low_open=True))
        s(self, "density", check_real(o, "density", self.density, MIN_DENSITY, 1e5, "kg/m^3"))
        if self.pressure is not None:
            # inflated strain q / (1 - q) with q = p R cos(pi/N) / (E h): in [-50 %, 100 %]
            s(self, "pressure", check_gauge_pressure(o, "pressure", self.pressure, self))
        s(self, "position", check_vector(o, "position", self.position, 1e6, "m"))
        s(self, "velocity", check_vector(o, "velocity", self.velocity, 1e3, "m/s"))
        s(
            self,
            "angular_velocity",
            check_real(o, "angular_velocity", self.angular_velocity, -1e5, 1e5, "rad/s"),
        )


@dataclass(frozen=True)
class Ground:
    """A ground half-plane: flat (angle 0), sloped, a wall or a ceiling; fixed, or moving rigidly.

    The surface moves with a constant ``velocity`` u plus an oscillation along its normal n, so
    that its offset along n is ``d(t) = d0 + n . u t + A sin(2 pi f t)`` and its velocity
    ``w(t) = u + A 2 pi f cos(2 pi f t) n`` (``ballenv.physics.ground.motion``). A node in contact
    ends each step on the surface with the surface's normal velocity; Coulomb friction acts on its
    velocity relative to the surface.

    Attributes:
        angle: angle a (rad) of the surface in [-pi, pi]; the normal into the free side is
            (-sin a, cos a): 0 is a floor, positive angles rise to the right, pi/2 a wall with the
            free side to its left (a right wall), -pi/2 a left wall, pi a ceiling.
        height: y (m) of a point of the surface at t = 0.
        friction: Coulomb coefficient mu in [0, 10] (0: frictionless).
        x: x (m) of that point (default 0): the surface passes through (x, height) at t = 0.
        velocity: constant velocity u (m/s) of the surface, each component in [-1000, 1000]: along
            the surface a conveyor belt, along its normal a rising or sinking plate.
        amplitude: amplitude A (m) of the oscillation along the normal, in [0, 100]; 0: none.
        frequency: its frequency f (Hz), in [0, 1e5]; above 0 when ``amplitude`` is.
    """

    angle: float = 0.0
    height: float = 0.0
    friction: float = 0.0
    x: float = 0.0
    velocity: tuple[float, float] = (0.0, 0.0)
    amplitude: float = 0.0
    frequency: float = 0.0

    def __post_init__(self) -> None:
        o = "Ground"
        s = object.__setattr__
        s(self, "angle", check_real(o, "angle", self.angle, -math.pi, math.pi, "rad"))
        s(self, "height", check_real(o, "height", self.height, -1e6, 1e6, "m"))
        s(self, "x", check_real(o, "x", self.x, -1e6, 1e6, "m"))
        s(self, "friction", check_real(o, "friction", self.friction, 0.0, 10.0))
        s(self, "velocity", check_vector(o, "velocity", self.velocity, 1e3, "m/s"))
        s(self, "amplitude", check_real(o, "amplitude", self.amplitude, 0.0, 100.0, "m"))
        oscillates = self.amplitude > 0.0
        unit = "Hz (above 0 when amplitude > 0)" if oscillates else "Hz"
        s(self, "frequency", check_real(o, "frequency", self.frequency, 0.0, 1e5, unit, low_open=oscillates))

    @property
    def moves(self) -> bool:
        """The surface moves: a velocity or an oscillation."""
        return self.velocity != (0.0, 0.0) or self.amplitude > 0.0


@dataclass(frozen=True)
class Drum:
    """A circular ground (a drum): the rings inside it or outside it, turning about its centre.

    The rings stay in ``R - |x - c| >= 0`` (``inside``) or ``|x - c| - R >= 0`` (outside: a round
    obstacle). The drum turns about its fixed centre ``c`` at the angular velocity (rad/s,
    counter-clockwise positive) ``Omega(t) = Omega_0 min(1, t / T)`` after a spin-up over ``T`` s
    (``ballenv.physics.ground.motion``), so its surface at ``x`` moves with
    ``w = Omega e_z x (x - c)``, along the surface. A node in contact ends each step on the circle;
    Coulomb friction acts on its velocity relative to ``w``, and the work the turning drum does
    through it is credited to the energy budget (``step.energy_budget.boundary_work``).

    Attributes:
        radius: radius R (m) of the circle, in (0, 1e6].
        centre: its centre c (m), each component in [-1e6, 1e6].
        inside: True (default): the rings are inside the drum; False: outside it.
        friction: Coulomb coefficient mu in [0, 10] (0: frictionless).
        angular_velocity: Omega_0 (rad/s) in [-1e4, 1e4]; 0: a fixed drum.
        spin_up: T (s) in [0, 1e6] over which Omega grows linearly from 0 to Omega_0; 0: none.
    """

    radius: float = 1.0
    centre: tuple[float, float] = (0.0, 0.0)
    inside: bool = True
    friction: float = 0.0
    angular_velocity: float = 0.0
    spin_up: float = 0.0

    def __post_init__(self) -> None:
        o = "Drum"
        s = object.__setattr__
        s(self, "radius", check_real(o, "radius", self.radius, 0.0, 1e6, "m", low_open=True))
        s(self, "centre", check_vector(o, "centre", self.centre, 1e6, "m"))
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


def _check_step_tolerances(scene: "Scene") -> None:
    """``impulse_tol`` and ``rtol``: each None or in range, and not both asking to control the step."""
    o, s = "Scene", object.__setattr__
    if scene.impulse_tol is not None:
        s(scene, "impulse_tol", check_real(o, "impulse_tol", scene.impulse_tol, 0.0, 10.0, "N s", True))
    if scene.rtol is not None:
        s(scene, "rtol", check_real(o, "rtol", scene.rtol, 0.0, 1.0))
    if scene.impulse_tol is not None and scene.rtol:
        raise ValueError(
            f"Scene.impulse_tol = {scene.impulse_tol!r} is invalid with Scene.rtol = {scene.rtol!r}: give "
            "one of them (rtol > 0 sets its own bound on the contact impulse; impulse_tol with rtol None "
            "or 0 turns error control off)"
        )
    if scene.adaptive and scene.step_rtol == 0.0 and scene.impulse_tol is None:
        raise ValueError(
            "Scene.impulse_tol = None is invalid with Scene.rtol = 0 and adaptive steps: the step then "
            "follows the contact impulse alone and needs its bound, in (0, 10] N s"
        )


@dataclass(frozen=True)
class Scene:
    """What to simulate: rings, the effects acting on them, and the numerical method.

    Attributes:
        rings: one or more :class:`Ring` (all with the same ``n_nodes``).
        grounds: any number of :class:`Ground` half-planes (none, and no drums: no contact work at all).
        drums: any number of :class:`Drum` circular grounds, the rings inside or outside them.
        contact: "mass_modification" (Baraff-Witkin: the contact set is updated inside the Newton
            iteration; the system keeps its size) or "predictor_corrector" (the paper's first
            method: the whole step is recomputed after each change of the contact set).
        impulse_tol: None (default) or the largest contact impulse per step ``f dt`` (N s) in (0, 10]:
            given, the adaptive step follows this absolute bound alone (error control off unless
            ``rtol`` > 0 is given too, which is an error). The impulse is a ring's total ground
            reaction over the step, net of the momentum that stops nodes moving into the ground at
            the step's start (arriving ones, or resting ones a collision impulse pushed; see
            ``step.stepper.try_step``); larger steps are rejected and shrunk by the ratio, smaller ones
            grow by at most x1.25.
        rtol: error control of the adaptive step, dimensionless in [0, 1]; None (default): 0.01
            (``DEFAULT_RTOL``) unless ``impulse_tol`` is given, then 0 (``step_rtol`` is the value in
            use). Above 0, every step keeps two measures within it: the local error estimate of the
            integrator (``step/local_error.py``), its RMS over a ring's nodes at most ``atol + rtol R``
            (m, ``R`` the ring's radius), and the error in contact as ``contact_error`` says, so the
            same ``rtol`` asks the same relative accuracy of a 3 g ring and a 500 g ball. What it
            achieves on six balls: ``benchmarks/accuracy.py`` (``benchmarks/results/accuracy.md``).
        contact_error: how ``rtol`` controls a step with a node on a ground at either end.
            "impulse" (default): the contact impulse (as for ``impulse_tol``) at most
            ``rtol M sqrt(g R)`` (N s, ``M`` the ring's mass: the momentum of the ring falling its own
            radius), and the step of a ring in flight ends at its predicted first touch of a ground
            (``ground/touchdown.py``). "doubling": the contact errors of ``step/contact_error.py`` (the
            distance arriving nodes still had to go, the step doubling of the ring's rigid motion, the contact
            impulse at most ``2 sqrt(rtol) M sqrt(g R)``): an error closer to proportional to ``rtol``
            (0.06-3.5 ``rtol`` on the six balls against 0.004-0.91, monotone on five of them against
            four), at about the same or more wall time than "impulse" for the same achieved error on
            five of the six (the stiff hoop: less).
        atol: absolute local error tolerance on positions (m) in [0, 1], added to ``rtol R``.
        friction_regularization: slip speed eps (m/s) in (0, 1] below which Coulomb friction is
            smoothed, ``mu N v / sqrt(v^2 + eps^2)``. A sticking node creeps at about eps times its
            tangential load over mu N (a ball rolling down a 0.2 rad slope: 0.5 mm/s at the default
            1e-2). Much smaller values (<= 1e-3) make Newton's iteration stall in sticking contact.
        gravity: magnitude g (m/s^2) along -y, in [0, 1000]; or a vector (gx, gy). 0 turns it off.
        damping: c (1/s) in [0, 1e6] of the deformation damping ``F_i = -c m (u_i - u_rigid,i)``.
        damping_mode: "rigid" (relative to the rigid motion: flight and spin undamped) or
            "centre_of_mass" (the paper's form, relative to the centre-of-mass velocity only).
        integrator: "generalized_alpha" (second order, default) or "backward_euler" (first order).
        rho_infinity: spectral radius at infinite frequency of generalized-alpha, in [0, 1]
            (1 = no numerical damping, trapezoidal rule; 0 = strongest high-frequency damping).
        dt: time step (s) in (0, 1]: the largest step when adaptive (default 0.01 s), or the fixed
            step.
        adaptive: True (default): adapt the step to the error (``rtol``) or the contact impulse
            (``impulse_tol``): a step above either is rejected and shrunk, accepted steps grow it
            by at most x1.25 back up to ``dt``. False: fixed steps ``dt`` (choose it: the default
            0.01 s is a largest step). Either way a rejected step (Newton failure, energy gain, intrusion,
            self-intersection) is retried with half the step; fixed, a halved step doubles back after each
            accepted step until it is ``dt`` again.
        dt_min: smallest step (s) before simulate() gives up with SimulationError, in (0, dt].
        newton_tol: Newton tolerance on the residual relative to the forces it balances
            (dimensionless), in [1e-14, 1e-2].
        newton_max_iter: Newton iterations before the step is rejected, in [1, 200].
        newton_rescue_max_iter: Newton iterations of a rescued step, in [0, 200]: when rejections
            for Newton failures have halved a step below ``dt_min``, the step is tried once more
            from the last accepted state and ``dt`` with this many iterations allowed, with the
            friction regularisation and, failing that, with it 10 and 100 times larger
            (``simulation.RESCUE_REGULARIZATION``: full Newton steps can cycle on Coulomb friction
            at any step size); the run stops only if all fail, and goes on with the scene's
            settings after a rescued step. At most ``newton_max_iter`` (e.g. 0): no rescue. A run
            that never stops at ``dt_min`` is the same whatever its value.
        atmospheric_pressure: p_atm (Pa) in [0, 1e7]; 0 gives the paper's ``p A = const``.
        gas_exponent: k in ``(p + p_atm) A^k = const`` in [0, 3] (1 isothermal, 1.4 adiabatic air;
            0 a regulated pressure: each ring's gauge pressure stays at its set value whatever its
            area, a line load ``p b`` with the potential ``-b p A``).
        ring_collision: rings push each other apart when a node comes within the contact distance
            ``h_a + h_b`` of another ring's centreline; only with two or more rings. With
            ``self_intersection = "barrier"`` through a barrier potential inside one implicit step
            of the rings in contact (``walls/ring_barrier.py``, ``step/joint_newton.py``), otherwise through
            explicit impulses (``walls/impulses.py``). False lets rings pass through each other.
        self_intersection: "barrier" (default: "reject", and wall parts of a ring far apart
            along it repel through a barrier potential inside the implicit step, with continuous
            collision detection on the Newton iterates, so a squashed ring rests folded;
            ``walls/self_barrier.py``; and a node folding shut or an edge collapsing meets a barrier of its
            own, ``walls/wall_limits.py``), "reject" (wall parts of a ring within a few edges of each other
            along the ring push apart like two rings, and a trial state in which a ring's polygon crosses
            itself is rejected and the step retried smaller; at ``dt_min`` simulate() stops with
            SimulationError) or "ignore" (neither).
    """

    rings: Sequence[Ring] = field(default_factory=lambda: (Ring(),))
    grounds: Sequence[Ground] = ()
    drums: Sequence[Drum] = ()
    contact: str = "mass_modification"
    impulse_tol: float | None = None
    rtol: float | None = None
    atol: float = 0.0
    contact_error: str = "impulse"
    friction_regularization: float = 1e-2
    gravity: float | tuple[float, float] = 9.81
    damping: float = 0.0
    damping_mode: str = "rigid"
    integrator: str = "generalized_alpha"
    rho_infinity: float = 0.9
    dt: float = 1e-2
    adaptive: bool = True
    dt_min: float = 1e-9
    newton_tol: float = 1e-9
    newton_max_iter: int = 25
    newton_rescue_max_iter: int = 200
    atmospheric_pressure: float = 101325.0
    gas_exponent: float = 1.0
    ring_collision: bool = True
    self_intersection: str = "barrier"

    def __post_init__(self) -> None:
        o = "Scene"
        s = object.__setattr__
        rings = check_sequence(o, "rings", self.rings, Ring, allow_empty=False)
        if len({r.n_nodes for r in rings}) != 1:
            fail(o, "rings", [r.n_nodes for r in rings], "rings with equal n_nodes")
        s(self, "rings", rings)
        s(self, "grounds", check_sequence(o, "grounds", self.grounds, Ground, allow_empty=True))
        s(self, "drums", check_sequence(o, "drums", self.drums, Drum, allow_empty=True))
        s(self, "contact", check_choice(o, "contact", self.contact, CONTACT_METHODS))
        _check_step_tolerances(self)
        s(self, "atol", check_real(o, "atol", self.atol, 0.0, 1.0, "m"))
        s(self, "contact_error", check_choice(o, "contact_error", self.contact_error, CONTACT_ERRORS))
        s(
            self,
            "friction_regularization",
            check_real(o, "friction_regularization", self.friction_regularization, 0.0, 1.0, "m/s", True),
        )
        if isinstance(self.gravity, Real) and not isinstance(self.gravity, bool):
            g = check_real(o, "gravity", self.gravity, 0.0, 1000.0, "m/s^2")
            s(self, "gravity", g)
        else:
            s(self, "gravity", check_vector(o, "gravity", self.gravity, 1000.0, "m/s^2"))
        s(self, "damping", check_real(o, "damping", self.damping, 0.0, 1e6, "1/s"))
        s(self, "damping_mode", check_choice(o, "damping_mode", self.damping_mode, DAMPING_MODES))
        s(self, "integrator", check_choice(o, "integrator", self.integrator, INTEGRATORS))
        s(self, "rho_infinity", check_real(o, "rho_infinity", self.rho_infinity, 0.0, 1.0))
        s(self, "dt", check_real(o, "dt", self.dt, 0.0, 1.0, "s", low_open=True))
        if not isinstance(self.adaptive, bool):
            fail(o, "adaptive", self.adaptive, "True or False")
        s(
            self,
            "dt_min",
            check_real(o, "dt_min", self.dt_min, 0.0, self.dt, "s (at most dt)", True),
        )
        s(self, "newton_tol", check_real(o, "newton_tol", self.newton_tol, 1e-14, 1e-2))
        s(self, "newton_max_iter", check_int(o, "newton_max_iter", self.newton_max_iter, 1, 200))
        s(
            self,
            "newton_rescue_max_iter",
            check_int(o, "newton_rescue_max_iter", self.newton_rescue_max_iter, 0, 200),
        )
        s(
            self,
            "atmospheric_pressure",
            check_real(o, "atmospheric_pressure", self.atmospheric_pressure, 0.0, 1e7, "Pa"),
        )
        s(self, "gas_exponent", check_real(o, "gas_exponent", self.gas_exponent, 0.0, 3.0))
        p_atm = self.atmospheric_pressure
        for i, ring in enumerate(rings):
            if ring.pressure is not None and ring.pressure < 0.0:
                check_gauge_pressure(o, f"rings[{i}].pressure", ring.pressure, ring, p_atm)
        if not isinstance(self.ring_collision, bool):
            fail(o, "ring_collision", self.ring_collision, "True or False")
        check_choice(o, "self_intersection", self.self_intersection, SELF_INTERSECTION)

    @property
    def step_rtol(self) -> float:
        """The relative tolerance the adaptive step keeps: ``rtol`` when given; otherwise 0 (error
        control off, the step follows ``impulse_tol``) when ``impulse_tol`` is given, else
        :data:`DEFAULT_RTOL`."""
        if self.rtol is not None:
            return self.rtol
        return 0.0 if self.impulse_tol is not None else DEFAULT_RTOL

    @property
    def gravity_vector(self) -> tuple[float, float]:
        """Gravitational acceleration (gx, gy) in m/s^2."""
        if isinstance(self.gravity, tuple):
            return self.gravity
        return (0.0, -self.gravity)
