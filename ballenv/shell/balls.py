"""Regulation balls as 3-D shells: a basketball, a football, a tennis ball and a volleyball.

A ball is a :class:`Ball`: a :class:`~ballenv.shell.Shell` (its wall and gas, at the origin), the
wall's :class:`Material` and the drop test of its rule (:class:`DropTest`). :func:`drop` runs a drop
test (its rule's, or from any height, at any pressure); :data:`BALLS` names the presets::

    from ballenv.shell.balls import basketball, drop

    ball = basketball()
    result = drop(ball)  # DropResult: rebound (m, as the rule measures it), contact time (s), ...
    scene = ball.scene(position=(0.0, 0.0, 1.0))  # the ball in a scene of one's own

How a preset is made (SI units):

* **radius, mass, pressure** from the rule (the middle of its ranges): ``r`` the inflated radius
  (circumference over 2 pi), ``M`` the mass, ``p`` the gauge pressure of the inflated ball.
* **wall**: a :class:`Material` (Young's modulus ``E``, Poisson ratio ``nu``, density ``rho``)
  whose thickness ``h = M / (rho A)`` gives the rule's mass, ``A`` the area of the rest mesh.
* **rest shape**: the inflated sphere stretched uniformly by ``lambda`` from the rest sphere of
  radius ``R = r / lambda``; the St. Venant-Kirchhoff membrane's balance with the gas,
  ``dW/dlambda = p dV/dlambda``, gives the Green strain ``G = (lambda^2 - 1) / 2 = p lambda a
  (1 - nu) / (2 E h)``, ``a = 3 V0 / A0`` (m, the rest mesh's volume over area; ``R`` for a sphere);
  the bending energy is zero under a uniform stretch. The gas's gauge pressure at the rest shape
  (``Shell.pressure``) is then ``p0 = (p + p_atm) lambda^3 - p_atm`` (the isothermal gas law).
* **loss**: one deformation damping ``c`` (1/s, ``Scene.damping``) per material, fitted by
  ``benchmarks/shell_balls.py`` so that one ball of the material (the one whose rule states a drop
  test) rebounds to the middle of its rule's range; every other rebound of that material (other
  balls, pressures, impact speeds) is a prediction. The fit holds for the mesh it was made on (a
  finer mesh loses less of the impact's energy at the same damping): ``c`` is fitted on 162 and on
  642 vertices (subdivisions 2 and 3), the meshes a preset can have. Results:
  ``benchmarks/results/shell_balls.md``.

A drop (:func:`drop`) releases the ball at rest onto a rigid, frictionless floor (the model has no
ground compliance: a rigid half-space), isothermal gas over 101,325 Pa, no air drag, with the
numerical settings of :data:`NUMERICS`. The fall is ballistic (the inflated ball falls without
deforming), so the run starts with the ball's bottom ``START_GAP`` above the floor at the speed of
its fall from the drop height. The rebound is measured as the rule measures it: the height of the
ball's lowest (or highest) vertex at the apex of the centre of mass (the apex located inside its
step, the vertices' offsets from the centre taken at the record nearest it).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..rules import FIBA_DROP, FIFA_DROP, ITF_DROP, DropTest
from .scene import ATMOSPHERIC_PRESSURE, Ground, Scene, Shell
from .simulation import Trajectory, simulate
from .skin.gas import volume
from .skin.mesh import icosphere, lumped_masses, triangle_areas

G = 9.81  # m/s^2
PSI = 6894.757  # Pa
KGF_PER_CM2 = 98066.5  # Pa
START_GAP = 0.01  # m: the ball's bottom above the floor when a drop's run starts
PEAK_WINDOW = 5e-4  # s: the ground reaction's peak is its mean over windows this long
NUMERICS: dict[str, Any] = {"rtol": 1e-4, "rho_infinity": 0.9, "integrator": "generalized_alpha"}


@dataclass(frozen=True)
class Material:
    """A ball's wall: youngs_modulus E (Pa), poisson_ratio nu, density rho (kg/m^3), and damping:
    the scene's deformation damping c (1/s) for each mesh (subdivisions k -> c) fitted on the drop
    test of ``fitted_on`` (a ball's name); source: where E, nu and rho come from."""

    name: str
    youngs_modulus: float
    poisson_ratio: float
    density: float
    damping: dict[int, float]
    fitted_on: str
    source: str


@dataclass(frozen=True)
class Ball:
    """A regulation ball: its shell at rest at the origin, its wall's material, its inflated radius
    (m) and gauge pressure (Pa), its rule's drop test (None where the rule states none) and the
    rule where its size, mass and pressure are stated."""

    name: str
    shell: Shell
    material: Material
    radius: float
    pressure: float
    drop_test: DropTest | None
    rule: str

    @property
    def damping(self) -> float:
        """The deformation damping c (1/s) of its material, fitted on its mesh."""
        return self.material.damping[self.shell.subdivisions]

    @property
    def mass(self) -> float:
        """Mass (kg): the lumped masses' sum."""
        area = float(triangle_areas(*_rest_mesh(self.shell)).sum())
        return self.shell.density * self.shell.thickness * area

    def pumped(self, pressure: float) -> Shell:
        """The same ball (rest radius, wall) with the gas that gives ``pressure`` (Pa gauge) when
        inflated (module doc)."""
        s = self.shell
        stretch = inflation_stretch(pressure, mesh_radius(s), s.youngs_modulus, s.poisson_ratio, s.thickness)
        p0 = (pressure + ATMOSPHERIC_PRESSURE) * stretch**3 - ATMOSPHERIC_PRESSURE
        return dataclasses.replace(s, pressure=p0)

    def scene(
        self,
        position: tuple[float, float, float] = (0.0, 0.0, 1.0),
        velocity: tuple[float, float, float] = (0.0, 0.0, 0.0),
        grounds: Sequence[Ground] = (Ground(),),
        pressure: float | None = None,
        damping: float | None = None,
        numerics: dict[str, Any] | None = None,
    ) -> Scene:
        """The ball centred at ``position`` (m) moving at ``velocity`` (m/s) above ``grounds``, with
        its material's damping (or ``damping``, 1/s) and :data:`NUMERICS` (``numerics``: other Scene
        keywords); ``pressure`` (Pa gauge, inflated) pumps the same ball to another pressure."""
        shell = self.shell if pressure is None else self.pumped(pressure)
        shell = dataclasses.replace(shell, position=position, velocity=velocity)
        c = self.damping if damping is None else damping
        return Scene(shells=[shell], grounds=grounds, damping=c, **{**NUMERICS, **(numerics or {})})


def _rest_mesh(shell: Shell) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    mesh = icosphere(shell.subdivisions, shell.radius)
    return mesh.vertices, mesh.triangles


def mesh_radius(shell: Shell) -> float:
    """``a = 3 V0 / A0`` (m) of the shell's rest mesh: its volume over its area (``R`` for a sphere)."""
    vertices, triangles = _rest_mesh(shell)
    return 3.0 * volume(vertices, triangles) / float(triangle_areas(vertices, triangles).sum())


def inflation_stretch(
    pressure: float, rest_radius: float, modulus: float, nu: float, thickness: float
) -> float:
    """The uniform stretch ``lambda`` of a rest sphere of radius ``a`` (m) inflated to ``pressure``
    (Pa gauge): the root of ``lambda^2 - 2 b lambda - 1 = 0``, ``b = p a (1 - nu) / (2 E h)``."""
    b = pressure * rest_radius * (1.0 - nu) / (2.0 * modulus * thickness)
    return b + math.sqrt(b * b + 1.0)


def regulation_shell(
    radius: float, mass: float, pressure: float, material: Material, subdivisions: int = 2
) -> Shell:
    """The shell of ``material`` whose inflated radius at gauge ``pressure`` (Pa) is ``radius`` (m)
    and whose mass is ``mass`` (kg) (module doc)."""
    for name, value, unit in (("radius", radius, "m"), ("mass", mass, "kg"), ("pressure", pressure, "Pa")):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and 0.0 < value < 1e8):
            raise ValueError(
                f"{name} = {value!r} is out of range: must be a finite number in (0, 1e8) {unit}"
            )
    if subdivisions not in material.damping:
        raise ValueError(
            f"subdivisions = {subdivisions!r} is out of range: must be one of {sorted(material.damping)}"
            f" (the meshes {material.name}'s damping is fitted on)"
        )
    unit_mesh = icosphere(subdivisions, 1.0)
    area1 = float(triangle_areas(unit_mesh.vertices, unit_mesh.triangles).sum())  # m^2 per R^2
    a1 = 3.0 * volume(unit_mesh.vertices, unit_mesh.triangles) / area1  # a / R
    E, nu, rho = material.youngs_modulus, material.poisson_ratio, material.density
    rest = radius
    for _ in range(50):  # R = r / lambda, h = M / (rho A(R)): a fixed point, contracting fast
        thickness = mass / (rho * area1 * rest * rest)
        g = pressure * radius * a1 * (1.0 - nu) / (2.0 * E * thickness)  # G = p lambda a (1 - nu) / (2 E h)
        rest = radius / math.sqrt(1.0 + 2.0 * g)
    stretch = radius / rest
    return Shell(
        radius=rest, subdivisions=subdivisions, youngs_modulus=E, poisson_ratio=nu, thickness=thickness,
        density=rho, pressure=(pressure + ATMOSPHERIC_PRESSURE) * stretch**3 - ATMOSPHERIC_PRESSURE,
        position=(0.0, 0.0, 0.0),
    )  # fmt: skip


@dataclass(frozen=True)
class DropResult:
    """What a drop measured (SI units).

    drop_height: of the ball's bottom at release (m); rebound: at the centre of mass's first apex
    after the bounce, the height (m) of the lowest vertex ("bottom") or the highest ("top"), as
    ``measured_to`` says; impact_speed: of the centre of mass at touchdown (m/s); restitution:
    ``sqrt(rise / drop_height)``, the centre of mass's rise above its height at touchdown (at rest
    shape) over the fall, its speed out over its speed in; contact_time: first touchdown to the
    last liftoff before the apex (s); peak_force: largest ground reaction (N), the mean over
    ``PEAK_WINDOW`` windows; pressure: the inflated ball's gauge pressure (Pa); trajectory: the
    run.
    """

    drop_height: float
    rebound: float
    measured_to: str
    impact_speed: float
    restitution: float
    contact_time: float
    peak_force: float
    pressure: float
    trajectory: Trajectory


def drop(
    ball: Ball,
    drop_height: float | None = None,
    pressure: float | None = None,
    damping: float | None = None,
    numerics: dict[str, Any] | None = None,
) -> DropResult:
    """Drop ``ball`` from ``drop_height`` (m, of its bottom; default its rule's, else 2 m) onto a
    rigid frictionless floor at z = 0 (``pressure``, ``damping``, ``numerics``: see
    :meth:`Ball.scene`), run past its first apex, measured as its rule measures (module doc)."""
    test = ball.drop_test
    height = drop_height if drop_height is not None else (test.drop_height if test else 2.0)
    if isinstance(height, bool) or not (isinstance(height, (int, float)) and START_GAP < height <= 100.0):
        raise ValueError(
            f"drop_height = {height!r} is out of range: must be a number in ({START_GAP}, 100] m"
        )
    to = test.measured_to if test else "bottom"
    p = ball.pressure if pressure is None else pressure
    offset = _bottom_offset(ball, p)
    speed, start = math.sqrt(2.0 * G * height), math.sqrt(2.0 * G * (height - START_GAP))
    scene = ball.scene((0.0, 0.0, START_GAP + offset), (0.0, 0.0, -start), pressure=p, damping=damping,
                       numerics=numerics)  # fmt: skip
    traj = simulate(scene, t_end=START_GAP / start + 0.04 + speed / G)
    return _measure(traj, height, to, speed, offset, p)


def _bottom_offset(ball: Ball, pressure: float) -> float:
    """The inflated ball's centre above its lowest vertex (m): ``lambda R``, the stretched pole."""
    s = ball.shell
    return s.radius * inflation_stretch(
        pressure, mesh_radius(s), s.youngs_modulus, s.poisson_ratio, s.thickness
    )


def _measure(
    traj: Trajectory, height: float, to: str, speed: float, offset: float, pressure: float
) -> DropResult:
    """The drop's :class:`DropResult` from its run (``offset``: the centre above the bottom at rest, m)."""
    touchdowns = [t for t, _, kind, _ in traj.events if kind == "touchdown"]
    apexes = traj.apexes()
    if not touchdowns or not len(apexes):
        raise RuntimeError(f"the drop from {height} m did not bounce to an apex within {traj.t[-1]:.3f} s")
    t_apex, z_apex = apexes[0]
    liftoffs = [t for t, _, kind, _ in traj.events if kind == "liftoff" and t < t_apex]
    mass = _masses(traj.scene.shells[0])
    k = int(np.argmin(np.abs(traj.t - t_apex)))  # the record nearest the apex
    z = traj.x[k, 0, :, 2]
    centre = float(mass @ z / mass.sum())
    rebound = z_apex - (centre - z.min()) if to == "bottom" else z_apex + (z.max() - centre)
    vz = traj.v[:, 0, :, 2] @ mass / mass.sum()
    return DropResult(
        drop_height=height, rebound=float(rebound), measured_to=to, impact_speed=speed,
        restitution=math.sqrt(max(z_apex - offset, 0.0) / height),
        contact_time=(liftoffs[-1] if liftoffs else math.nan) - touchdowns[0],
        peak_force=peak_force(traj.t, vz, float(mass.sum())), pressure=pressure, trajectory=traj,
    )  # fmt: skip


def _masses(shell: Shell) -> NDArray[np.float64]:
    """The shell's lumped vertex masses (kg), (V,)."""
    return lumped_masses(icosphere(shell.subdivisions, shell.radius), shell.density, shell.thickness)


def peak_force(t: NDArray[np.float64], vz: NDArray[np.float64], mass: float) -> float:
    """Largest mean ground reaction (N) over ``PEAK_WINDOW``: the contact impulse ``J(t) = M (v(t) -
    v(0)) + M g t`` (the ball's momentum balance; ``vz`` its centre's upward velocity, m/s, at times
    ``t``, s) differenced over the window, on a grid of a tenth of it."""
    impulse = mass * (vz - vz[0]) + mass * G * (t - t[0])
    grid = np.arange(t[0], t[-1] - PEAK_WINDOW, PEAK_WINDOW / 10.0)
    j0 = np.interp(grid, t, impulse)
    j1 = np.interp(grid + PEAK_WINDOW, t, impulse)
    return float(np.max(j1 - j0) / PEAK_WINDOW)


FIBA = (
    "FIBA Official Basketball Rules 2020, Basketball Equipment, 2 (size 7: circumference 749-780 mm,"
    " mass 567-650 g; no pressure: the one that passes the drop test)"
)
FIFA = (
    "FIFA Quality Programme for Footballs, FIFA Quality Pro (circumference 68.5-69.5 cm, mass"
    " 420-445 g, tested at 0.8 bar gauge)"
)
ITF = (
    "ITF Rules of Tennis, Appendix I (type 2: diameter 6.54-6.86 cm, mass 56.0-59.4 g; no pressure:"
    " a pressurised ball holds about 12 psi above the atmosphere, as University of Illinois Physics"
    " Van's Tennis ball facts states; a maker, Artengo, states about 0.8 bar)"
)
FIVB = (
    "FIVB Official Volleyball Rules, 3.1 (circumference 65-67 cm, mass 260-280 g, inside pressure"
    " 0.300-0.325 kg/cm^2; no drop test)"
)

# damping (1/s) fitted by benchmarks/shell_balls.py (the middle of the rule's rebound range), on
# each mesh: subdivisions 2 (162 vertices) and 3 (642)
FITTED_DAMPING = {
    "basketball carcass": {2: 634.1, 3: 749.0},
    "synthetic leather": {2: 472.5, 3: 578.4},
    "tennis rubber": {2: 881.4, 3: 994.2},
}

CARCASS = Material(
    "basketball carcass", 20e6, 0.45, 1100.0, FITTED_DAMPING["basketball carcass"], "basketball",
    "an effective modulus of the wound carcass (rubber bladder, nylon windings, rubber or composite"
    " cover), the ring's basketball's; rubber's density",
)  # fmt: skip
LEATHER = Material(
    "synthetic leather", 20e6, 0.4, 950.0, FITTED_DAMPING["synthetic leather"], "football",
    "an effective modulus of synthetic-leather panels over a lined latex bladder, the ring's"
    " football's; the density of polyurethane-coated fabric and foam",
)  # fmt: skip
TENNIS_RUBBER = Material(
    "tennis rubber", 5e6, 0.49, 1250.0, FITTED_DAMPING["tennis rubber"], "tennis_ball",
    "a filled natural rubber of 65-70 Shore A (4.4-5.5 MPa by Gent's relation of hardness to"
    " modulus), nearly incompressible; the density of filled rubber, the felt's mass included",
)  # fmt: skip


def basketball(subdivisions: int = 2) -> Ball:
    """FIBA size 7: circumference 765 mm, 608.5 g, 8 psi (55.2 kPa, the middle of the NBA's
    7.5-8.5 psi); the basketball carcass."""
    r, p = 0.765 / (2.0 * math.pi), 8.0 * PSI
    shell = regulation_shell(r, 0.6085, p, CARCASS, subdivisions)
    return Ball("basketball", shell, CARCASS, r, p, FIBA_DROP, FIBA)


def football(subdivisions: int = 2) -> Ball:
    """FIFA Quality Pro size 5: circumference 69 cm, 432.5 g, 0.8 bar (80 kPa) gauge; synthetic
    leather."""
    r, p = 0.69 / (2.0 * math.pi), 80e3
    shell = regulation_shell(r, 0.4325, p, LEATHER, subdivisions)
    return Ball("football", shell, LEATHER, r, p, FIFA_DROP, FIFA)


def tennis_ball(subdivisions: int = 2) -> Ball:
    """ITF type 2: diameter 6.70 cm, 57.7 g, 12 psi (82.7 kPa) gauge; tennis rubber."""
    r, p = 0.0335, 12.0 * PSI
    shell = regulation_shell(r, 0.0577, p, TENNIS_RUBBER, subdivisions)
    return Ball("tennis_ball", shell, TENNIS_RUBBER, r, p, ITF_DROP, ITF)


def volleyball(subdivisions: int = 2) -> Ball:
    """FIVB: circumference 66 cm, 270 g, 0.3125 kg/cm^2 (30.6 kPa) gauge; synthetic leather, the
    football's material and damping: its drop is a prediction."""
    r, p = 0.66 / (2.0 * math.pi), 0.3125 * KGF_PER_CM2
    shell = regulation_shell(r, 0.270, p, LEATHER, subdivisions)
    return Ball("volleyball", shell, LEATHER, r, p, None, FIVB)


BALLS: dict[str, Callable[..., Ball]] = {
    "basketball": basketball,
    "football": football,
    "tennis_ball": tennis_ball,
    "volleyball": volleyball,
}
