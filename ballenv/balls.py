"""Regulation balls as 2-D rings, calibrated so that each passes its rule's drop test.

A ball is a :class:`Ball`: a :class:`~ballenv.physics.Ring` (its wall and gas), the scene's
deformation damping, the numerical settings it was calibrated with, and the drop test of its rule
(:class:`DropTest`). :func:`drop` runs that test on the simulator; :data:`BALLS` names the presets::

    from ballenv.balls import basketball, drop

    ball = basketball()
    result = drop(ball)  # DropResult: rebound (m), contact time (s), peak force (N), ...
    scene = ball.scene(position=(0.0, 1.0))  # the ball in a scene of one's own (floor below)

How a preset is made (SI units):

* **radius and mass** are the rule's (mid-range): the ring's inflated radius ``r`` at the rule's
  pressure ``p`` is the ball's radius, so its rest radius is ``R = r / (1 + r p cos(pi/N) / (E h))``
  (from ``r = R / (1 - q)``, :mod:`ballenv.physics.base.ring`); its density is the one that gives the
  ball's mass ``M = N rho b h l0``.
* **width** ``b = 2 r``: the ring is the ball's central slice, as wide as the ball. The gas then
  pushes on the ground over about the same area as the ball's flattened patch, and the contact
  times come out near those of a gas-filled sphere, ``pi sqrt(M / (2 pi r p))`` (a membrane
  flattening on the ground: contact force ``2 pi r p d`` at compression ``d``).
* **wall** ``E`` and ``h``: the wall's thickness and an effective modulus of its carcass (rubber,
  windings, panels), which sets how much the gas stretches it (8-17 %: ``p r cos(pi/N) / (E h)``).
* **pressure**: the rule's, or a typical one where the rule leaves it open (stated per ball).
* **damping** ``c`` (1/s, ``Scene.damping``): fitted by ``benchmarks/ball_calibration.py``
  (scipy's ``brentq``) so that the drop test's rebound is the middle of the rule's range, with the
  ball's own numerical settings (``Ball.fidelity``). The results, with contact times, peak forces
  and the rebound against pressure: ``benchmarks/results/ball_calibration.md``.

The gas follows the isothermal gas law over the atmosphere (``gas_exponent`` 1, ``p_atm``
101,325 Pa); the ground is rigid and frictionless; no air drag.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ballenv.physics import Ground, Ring, Scene, simulate
from ballenv.physics.base.ring import inflated_radius, rest_edge_length, total_mass

from .physics.presets import with_fidelity
from .rules import FIBA_DROP, FIFA_DROP, ITF_DROP, DropTest

P_ATM = 101325.0  # Pa
G = 9.81  # m/s^2
PSI = 6894.757  # Pa
PEAK_WINDOW = 5e-4  # s: the ground reaction's peak is its mean over windows this long


@dataclass(frozen=True)
class Ball:
    """A calibrated ball: its ring, damping and numerical settings, and its rule's drop test.

    Attributes:
        name: the ball's name.
        ring: the ball at rest at the origin (m, kg, Pa: see :class:`~ballenv.physics.Ring`).
        damping: ``Scene.damping`` c (1/s) of the wall's deformation.
        drop_test: its rule's drop test, or None where the rule states none.
        rule: where the ball's size, mass and pressure are stated.
        fidelity: the numerical preset it was calibrated with (``ballenv.physics.presets``).
    """

    name: str
    ring: Ring
    damping: float
    drop_test: DropTest | None
    rule: str
    fidelity: str = "balanced"

    @property
    def mass(self) -> float:
        """Mass (kg)."""
        return total_mass(self.ring)

    @property
    def radius(self) -> float:
        """Radius (m) of the inflated ball at rest."""
        return inflated_radius(self.ring)

    def scene(
        self,
        position: tuple[float, float] = (0.0, 1.0),
        velocity: tuple[float, float] = (0.0, 0.0),
        grounds: Sequence[Ground] = (Ground(),),
        pressure: float | None = None,
        numerics: dict[str, Any] | None = None,
    ) -> Scene:
        """The ball centred at ``position`` (m) moving at ``velocity`` (m/s) above ``grounds``, with
        its damping, the gas law over the atmosphere and its numerical settings; ``pressure``
        (Pa, gauge at rest) pumps the same ball (same rest radius and wall) to another pressure;
        ``numerics`` (Scene keywords) replace settings of its fidelity preset."""
        ring = dataclasses.replace(
            self.ring,
            position=position,
            velocity=velocity,
            pressure=self.ring.pressure if pressure is None else pressure,
        )
        scene = Scene(rings=[ring], grounds=grounds, damping=self.damping, atmospheric_pressure=P_ATM)
        return dataclasses.replace(with_fidelity(scene, self.fidelity), **(numerics or {}))


@dataclass(frozen=True)
class DropResult:
    """What a drop test measured (SI units).

    Attributes:
        drop_height: height (m) of the ball's bottom at release.
        rebound: rebound height (m) measured as the test says (to the bottom or the top).
        impact_speed: speed (m/s) of the centre of mass at touchdown.
        restitution: rebound over impact speed of the centre of mass, ``sqrt(rise / fall)`` of the
            centre after and before touchdown.
        contact_time: touchdown to lift-off (s).
        peak_force: largest ground reaction (N), mean over ``PEAK_WINDOW`` windows.
        pressure: the ball's gauge pressure at rest (Pa).
    """

    drop_height: float
    rebound: float
    impact_speed: float
    restitution: float
    contact_time: float
    peak_force: float
    pressure: float


def drop(
    ball: Ball,
    pressure: float | None = None,
    drop_height: float | None = None,
    numerics: dict[str, Any] | None = None,
) -> DropResult:
    """Run ``ball``'s drop test (its rule's height, or ``drop_height`` in m, of the ball's bottom;
    at ``pressure`` Pa if given; ``numerics``: see :meth:`Ball.scene`): the ball released at rest
    above a rigid frictionless floor, run past its first apex. A ball without a drop test is
    dropped from ``drop_height`` (default 2 m) and its rebound measured to its bottom."""
    test = ball.drop_test
    height = drop_height if drop_height is not None else (test.drop_height if test else 2.0)
    to_top = test is not None and test.measured_to == "top"
    probe = ball.scene(pressure=pressure, numerics=numerics).rings[0]
    r = inflated_radius(probe)
    scene = ball.scene(position=(0.0, height + r), pressure=pressure, numerics=numerics)
    fall = math.sqrt(2.0 * height / G)
    traj = simulate(scene, 2.1 * fall + 0.05)
    times = {kind: [t for t, _, k in traj.events if k == kind] for kind in ("touchdown", "liftoff")}
    touchdown, liftoff = times["touchdown"][0], times["liftoff"][0]
    apex = traj.apexes()[0, 1]
    return DropResult(
        drop_height=height,
        rebound=apex + r if to_top else apex - r,
        impact_speed=math.sqrt(2.0 * G * height),
        restitution=math.sqrt(max(apex - r, 0.0) / height),
        contact_time=liftoff - touchdown,
        peak_force=_peak_force(traj.t, traj.v[:, 0, :, 1].mean(axis=1), total_mass(probe)),
        pressure=float(probe.pressure or 0.0),
    )


def _peak_force(t, vy, mass):
    """Largest mean ground reaction (N) over ``PEAK_WINDOW``: the contact impulse ``J(t) = M (v(t) -
    v(0)) + M g t`` (momentum balance of the ball, centre-of-mass velocity ``vy`` m/s at times ``t``
    s) differenced over the window, on a grid of a tenth of it."""
    impulse = mass * (vy - vy[0]) + mass * G * (t - t[0])
    grid = np.arange(t[0], t[-1] - PEAK_WINDOW, PEAK_WINDOW / 10.0)
    j0 = np.interp(grid, t, impulse)
    j1 = np.interp(grid + PEAK_WINDOW, t, impulse)
    return float(np.max(j1 - j0) / PEAK_WINDOW)


def regulation_ring(
    radius: float,
    mass: float,
    pressure: float,
    youngs_modulus: float,
    thickness: float,
    width: float,
    n_nodes: int = 64,
) -> Ring:
    """The ring whose inflated radius at gauge ``pressure`` (Pa) is ``radius`` (m) and whose mass is
    ``mass`` (kg), with wall ``youngs_modulus`` (Pa), ``thickness`` and ``width`` (m): rest radius
    ``R = r / (1 + r p cos(pi/N) / (E h))``, density ``M / (N b h l0)``."""
    rest = radius / (1.0 + radius * pressure * math.cos(math.pi / n_nodes) / (youngs_modulus * thickness))
    density = mass / (n_nodes * width * thickness * rest_edge_length(rest, n_nodes))
    return Ring(
        radius=rest, n_nodes=n_nodes, youngs_modulus=youngs_modulus, thickness=thickness,
        width=width, density=density, pressure=pressure, position=(0.0, 0.0),
    )  # fmt: skip


FIBA = (
    "FIBA Official Basketball Rules 2020, Basketball Equipment, 2 (size 7: circumference 749-780 mm,"
    " mass 567-650 g; the pressure is the one that passes the drop test)"
)
ITF = "ITF Rules of Tennis, Appendix I (type 2: diameter 6.54-6.86 cm, mass 56.0-59.4 g)"
FIFA = (
    "FIFA Quality Programme for Footballs, FIFA Quality Pro (circumference 68.5-69.5 cm, mass"
    " 420-445 g, tested at 0.8 bar)"
)
FIVB = "FIVB Official Volleyball Rules, 3.1 (circumference 65-67 cm, mass 260-280 g, 0.300-0.325 kgf/cm^2)"

# damping (1/s) fitted by benchmarks/ball_calibration.py: the middle of each rule's rebound range
FITTED_DAMPING = {
    "basketball": 96.96,
    "tennis_ball": 202.66,
    "football": 23.63,
    "paper_basketball": 82.78,
    "paper_tennis_ball": 20.60,
}


def basketball() -> Ball:
    """FIBA size 7: circumference 765 mm (r = 12.18 cm), 608.5 g, 8 psi (55.2 kPa, the middle of
    the NBA's 7.5-8.5 psi); wall E = 20 MPa, h = 3 mm (inflated strain 11 %)."""
    ring = regulation_ring(0.765 / (2 * math.pi), 0.6085, 8.0 * PSI, 20e6, 3e-3, 0.765 / math.pi)
    return Ball("basketball", ring, FITTED_DAMPING["basketball"], FIBA_DROP, FIBA)


def tennis_ball() -> Ball:
    """ITF type 2: diameter 6.70 cm, 57.7 g, 12 psi (82.7 kPa) above the atmosphere (a pressurised
    ball; the ITF states no pressure); rubber wall E = 5 MPa, h = 3.3 mm (inflated strain 17 %)."""
    ring = regulation_ring(0.0335, 0.0577, 12.0 * PSI, 5e6, 3.3e-3, 0.067)
    return Ball("tennis_ball", ring, FITTED_DAMPING["tennis_ball"], ITF_DROP, ITF)


def football() -> Ball:
    """FIFA Quality Pro size 5: circumference 69 cm (r = 10.98 cm), 432.5 g, 0.8 bar (the test's
    pressure, inside the Laws of the Game's 0.6-1.1 atm); wall E = 20 MPa, h = 3 mm (inflated
    strain 15 %)."""
    ring = regulation_ring(0.69 / (2 * math.pi), 0.4325, 80e3, 20e6, 3e-3, 0.69 / math.pi)
    return Ball("football", ring, FITTED_DAMPING["football"], FIFA_DROP, FIFA)


def volleyball() -> Ball:
    """FIVB: circumference 66 cm (r = 10.50 cm), 270 g, 0.3125 kgf/cm^2 (30.6 kPa); wall E = 20 MPa,
    h = 2 mm (inflated strain 8 %). The FIVB rules state no drop test: its damping is the
    football's (a bladder in synthetic-leather panels too), and its drop from 2 m is a prediction,
    not a calibration."""
    ring = regulation_ring(0.66 / (2 * math.pi), 0.270, 0.3125 * 98066.5, 20e6, 2e-3, 0.66 / math.pi)
    return Ball("volleyball", ring, FITTED_DAMPING["football"], None, FIVB)


def paper_basketball() -> Ball:
    """The paper's basketball-like ring (figure 7): R = 0.12 m, h = 2 mm, E = 25 MPa, p = 30 kPa,
    b = 2 cm, rho = 1100 kg/m^3 (33 g), with the damping that passes FIBA's drop test."""
    ring = Ring(
        radius=0.12, n_nodes=64, youngs_modulus=25e6, thickness=2e-3, width=0.02, density=1100.0,
        pressure=30e3, position=(0.0, 0.0),
    )  # fmt: skip
    return Ball(
        "paper_basketball", ring, FITTED_DAMPING["paper_basketball"], FIBA_DROP, "the paper, figure 7"
    )


def paper_tennis_ball() -> Ball:
    """The paper's tennis-ball-like ring (figure 7): R = 5 cm, h = 6 mm, E = 10 MPa, p = 4 kPa,
    b = 2 cm, rho = 1100 kg/m^3 (41 g), with the damping that passes the ITF's drop test. Its wall
    bends more than the gas holds it (``p R^3 / (EI/b)`` = 3): the "balanced" preset's rebound is
    off by 5 cm, so it runs at "accurate"."""
    ring = Ring(
        radius=0.05, n_nodes=64, youngs_modulus=10e6, thickness=6e-3, width=0.02, density=1100.0,
        pressure=4e3, position=(0.0, 0.0),
    )  # fmt: skip
    return Ball(
        "paper_tennis_ball", ring, FITTED_DAMPING["paper_tennis_ball"], ITF_DROP, "the paper, figure 7",
        fidelity="accurate",
    )  # fmt: skip


BALLS: dict[str, Callable[[], Ball]] = {
    "basketball": basketball,
    "tennis_ball": tennis_ball,
    "volleyball": volleyball,
    "football": football,
    "paper_basketball": paper_basketball,
    "paper_tennis_ball": paper_tennis_ball,
}
