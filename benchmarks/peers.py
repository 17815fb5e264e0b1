"""Peer benchmark: ballenv against PyElastica 1.0.0 on the same scene in the same run; the wall-time
ratio at matched first-apex accuracy.

    python benchmarks/peers.py          # writes benchmarks/results/peers.md
    python benchmarks/peers.py --quick  # fewer settings, coarser reference, one repeat

Needs PyElastica: ``pip install 'ballenv[peers]'`` (without it the script says so and exits with
status 2).

The scene, the "1-s drop": one ring (R = 0.1 m, N = 64, E = 10 MPa, h = 2 mm, b = 2.09 mm,
rho = 1100 kg/m^3, 1 kPa gauge at rest, so it starts inflated to the circle where its wall tension
holds that pressure) released at rest with its centre at 1 m; gas law ``p A = const``
(``atmospheric_pressure = 0``), gravity 9.81 m/s^2, no damping, one frictionless floor; 1 s
simulated: it falls, bounces and rises to a first apex (centre-of-mass height), the measured
quantity.

ballenv: a converged reference (fixed generalized-alpha steps of 2^-17 s, checked by halving), then
the named step-control settings of :data:`BALLENV_SETTINGS`, each with its first-apex error against
the reference and its wall time. Fixed steps are binary fractions of a second (2^-k s), so that the
fixed-step clock sums exactly: with dt = 1.25e-5 s its round-off drifted past the grid tolerance
(1e-9 dt) after about 10^4 steps, a 1e-14 s step followed, and the run failed on the energy guard
at t = 0.129 s.

PyElastica: a closed Cosserat rod (``CosseratRod.ring_rod``) of 64 nodes and elements on the same
rest circle, planar motion in x-y, with ballenv's node mass (cross-section area ``b h``), stretching
stiffness ``EA = E b h`` and in-plane bending stiffness ``EI = E b h^3 / 12`` (set in the bend
matrix: the equivalent disc radius matches one of them, not both), and the rectangle's rotary
inertia ``rho b h^3 / 12`` per length for the in-plane rotation. Shear: ``alpha G A`` with
PyElastica's ``alpha = 27/28`` and ``G = E/3`` (its default, Poisson ratio 1/2) times a factor; a
stiffer shear brings the rod closer to ballenv's unshearable one but shrinks the stable step as
1/sqrt(G). The gas is a custom external force (``p = C / A`` from the polygon's area, ``p b |e|``
along each edge's outward normal, half to each end node: ballenv's force exactly), gravity is
PyElastica's ``GravityForces``. The floor is a custom constraint on the nodes (``Floor``): a node
below y = 0 is put on it and its downward velocity removed after each kinematic and dynamic stage,
and it leaves freely; this is ballenv's contact law (frictionless, inelastic per node, no
penetration). PyElastica's own ``RodPlaneContact`` (a penalty spring-damper on element centres)
cannot be used: in 1.0.0 its kernel assumes an open rod (elements = nodes - 1) and fails on a ring
rod with a broadcasting error. Integrator: ``PositionVerlet`` near its largest stable step, which
is set by the in-plane rotation of the directors against the shear spring and the bending of the
zigzag mode (:func:`stable_step_estimate`): 2.09e-5 s at G = E/3 (measured: 2.0e-5 s runs, 2.1e-5 s
diverges), so dt = 1.9e-5 s, the headline run. The other PyElastica runs halve that step and
stiffen the shear (10x and 30x, at steps 10 % under their limits): they show where PyElastica's
apex differs from ballenv's and why.

Wall times (median of repeats, OPENBLAS_NUM_THREADS=1, both codes' numba kernels compiled before
timing): ballenv's ``SimulationStats.wall_time`` (building the simulation and stepping);
PyElastica's stepping loop only (building the rod, ``finalize`` and the compilation excluded), with
the centre of mass read every 50 steps to find the apex. Both run in one process on one core; the
headline ratio comes from runs of the two codes taken in alternation (other jobs on a shared
machine shift both alike).
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import functools  # noqa: E402
import importlib.metadata  # noqa: E402
import importlib.util  # noqa: E402
import math  # noqa: E402
import pathlib  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numba  # noqa: E402
import numpy as np  # noqa: E402

import ballenv  # noqa: E402
from ballenv.files import write_text  # noqa: E402
from ballenv.physics import Ground, Ring, Scene, simulate  # noqa: E402
from ballenv.physics.base.ring import bending_stiffness, inflated_radius, rest_area  # noqa: E402
from ballenv.physics.presets import FIDELITY_PRESETS, with_fidelity  # noqa: E402
from ballenv.physics.simulation import SimulationError  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
INSTALL_HINT = "pip install 'ballenv[peers]'"
T_END = 1.0  # s
GRAVITY = 9.81  # m/s^2
RING = dict(
    radius=0.1, n_nodes=64, youngs_modulus=10e6, thickness=2e-3, width=2.09e-3, density=1100.0,
    pressure=1e3, position=(0.0, 1.0),
)  # fmt: skip
# First apex (m) of the reference below, measured with this benchmark (2^-18 s moves it by 1.4e-7 m);
# the tests check quick runs against it.
REFERENCE_APEX = 0.577405
ONE_PERCENT = 0.01


def _tol(value):
    """1e-4 -> '1e-4' (labels of tolerances)."""
    return f"{value:.0e}".replace("e-0", "e-")


# ---------------------------------------------------------------------------- the settings compared
# ballenv's settings: (label, numerics). numerics are Scene fields (any of them: the lead's new step
# control knobs go here as they land), plus "fidelity" (a preset of ballenv.physics.presets, applied
# first; it sets its own node count) and "n_nodes". Edit this list only to compare other settings.
REFERENCE = ("GA fixed dt=2^-17 (reference)", dict(adaptive=False, dt=2.0**-17))
REFERENCE_CHECK = ("GA fixed dt=2^-18", dict(adaptive=False, dt=2.0**-18))
QUICK_REFERENCE = ("GA fixed dt=2^-15 (quick reference)", dict(adaptive=False, dt=2.0**-15))
BALLENV_SETTINGS = [
    *[(f"GA fixed dt=2^-{k}", dict(adaptive=False, dt=2.0**-k)) for k in (9, 10, 11, 12, 13, 14)],
    ("GA fixed dt=2^-12, rho_inf=0.3", dict(adaptive=False, dt=2.0**-12, rho_infinity=0.3)),
    ("BE fixed dt=2^-14", dict(integrator="backward_euler", adaptive=False, dt=2.0**-14)),
    *[
        (f"GA adaptive dt<=1e-2 tol={_tol(tol)}", dict(adaptive=True, dt=1e-2, impulse_tol=tol))
        for tol in (5e-3, 1e-3, 2e-4, 1e-4, 5e-5, 2e-5)
    ],
    *[
        (f"GA adaptive dt<=2e-3 tol={_tol(tol)}", dict(adaptive=True, dt=2e-3, impulse_tol=tol))
        for tol in (2e-4, 1e-4, 5e-5)
    ],
    *[
        (f"GA adaptive dt<=1e-3 tol={_tol(tol)}", dict(adaptive=True, dt=1e-3, impulse_tol=tol))
        for tol in (1e-3, 2e-4, 1e-4, 5e-5, 2e-5)
    ],
    (
        "GA adaptive dt<=1e-3 tol=1e-4, newton_tol=1e-6",
        dict(adaptive=True, dt=1e-3, impulse_tol=1e-4, newton_tol=1e-6),
    ),
    (
        "GA adaptive dt<=1e-3 tol=1e-4, rho_inf=0.3",
        dict(adaptive=True, dt=1e-3, impulse_tol=1e-4, rho_infinity=0.3),
    ),
    *[
        (f"GA adaptive dt<=1e-2 rtol={_tol(rtol)}", dict(adaptive=True, dt=1e-2, rtol=rtol))
        for rtol in (1e-1, 3e-2, 1e-2, 3e-3, 1e-3)
    ],
    # more numerical damping of the wall modes the error control need not follow: after the bounce
    # the light ring rings, and at rho_inf 0.9 the steps stay short until the end
    *[
        (
            f"GA adaptive dt<=1e-2 rtol={_tol(rtol)}, rho_inf={rho}",
            dict(adaptive=True, dt=1e-2, rtol=rtol, rho_infinity=rho),
        )
        for rtol in (3e-2, 1e-2)
        for rho in (0.5, 0.3)
    ],
    # the same with a looser Newton tolerance, or a longer largest step (the flight's steps)
    (
        "GA adaptive dt<=1e-2 rtol=3e-2, rho_inf=0.3, newton_tol=1e-6",
        dict(adaptive=True, dt=1e-2, rtol=3e-2, rho_infinity=0.3, newton_tol=1e-6),
    ),
    (
        "GA adaptive dt<=2e-2 rtol=3e-2, rho_inf=0.3",
        dict(adaptive=True, dt=2e-2, rtol=3e-2, rho_infinity=0.3),
    ),
    ("Scene() default (adaptive dt<=1e-2 rtol=1e-2)", dict()),
    *[(f"preset {name} (N={p['n_nodes']})", dict(fidelity=name)) for name, p in FIDELITY_PRESETS.items()],
]
QUICK_BALLENV = ("GA fixed dt=2^-11", "GA adaptive dt<=1e-3 tol=1e-4", "preset balanced (N=64)")

# PyElastica's settings: (label, dt (s), shear factor: G in units of E/3). The first is the headline.
ELASTICA_SETTINGS = [
    ("PositionVerlet, G=E/3, near its largest stable dt", dict(dt=1.9e-5, shear=1.0)),
    ("PositionVerlet, G=E/3, dt halved", dict(dt=0.95e-5, shear=1.0)),
    ("PositionVerlet, G=10 E/3, near its largest stable dt", dict(dt=6e-6, shear=10.0)),
    ("PositionVerlet, G=30 E/3, near its largest stable dt", dict(dt=3.5e-6, shear=30.0)),
    ("PositionVerlet, G=E/3, dt=2.1e-5 (above the limit)", dict(dt=2.1e-5, shear=1.0)),
]
QUICK_ELASTICA = ("PositionVerlet, G=E/3, near its largest stable dt",)


@dataclasses.dataclass
class Result:
    """One measured run of the drop: first apex (m), its relative error, wall and CPU time (s, medians
    of the repeats), steps."""

    code: str
    label: str
    settings: str
    steps: int
    wall: float
    cpu: float
    apex: float
    error: float = math.nan
    note: str = ""


def timed(fn, *args, **kwargs):
    """(fn's value, wall time s, CPU time s of this process) of one call."""
    wall, cpu = time.perf_counter(), time.process_time()
    value = fn(*args, **kwargs)
    return value, time.perf_counter() - wall, time.process_time() - cpu


def settings_text(numerics):
    return ", ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in numerics.items())


# ------------------------------------------------------------------------------------ ballenv side
def drop_scene(**numerics):
    """The 1-s drop as a ballenv Scene with ``numerics`` (see :data:`BALLENV_SETTINGS`)."""
    numerics = dict(numerics)
    fidelity = numerics.pop("fidelity", None)
    ring = Ring(**{**RING, "n_nodes": numerics.pop("n_nodes", RING["n_nodes"])})
    scene = Scene(rings=[ring], grounds=[Ground(friction=0.0)], atmospheric_pressure=0.0, gravity=GRAVITY)
    if fidelity is not None:
        scene = with_fidelity(scene, fidelity)
    if "dt" in numerics and "dt_min" not in numerics:
        numerics["dt_min"] = min(scene.dt_min, numerics["dt"])
    return dataclasses.replace(scene, **numerics)


def run_ballenv(label, numerics, repeats=3):
    """Result of ballenv on the drop with ``numerics``: times of ``simulate`` (building and stepping),
    medians of ``repeats`` warm runs (a failed run gives apex NaN and the failure in ``note``)."""
    scene = drop_scene(**numerics)
    simulate(scene, 1e-3)  # compile, or load the cache for this scene's kernels
    walls, cpus = [], []
    for _ in range(repeats):
        try:  # apexes are events, located inside the steps: record the end only
            traj, wall, cpu = timed(simulate, scene, T_END, output_dt=T_END)
        except SimulationError as exc:
            s = exc.trajectory.stats
            text = settings_text(numerics)
            return Result("ballenv", label, text, s.steps, s.wall_time, s.wall_time, math.nan, note=str(exc))
        walls.append(wall)
        cpus.append(cpu)
    apexes = traj.apexes()
    apex = float(apexes[0, 1]) if len(apexes) else math.nan
    wall, cpu = float(np.median(walls)), float(np.median(cpus))
    return Result("ballenv", label, settings_text(numerics), traj.stats.steps, wall, cpu, apex)


# --------------------------------------------------------------------------------- PyElastica side
def elastica_available():
    return importlib.util.find_spec("elastica") is not None


@numba.njit(cache=True)
def gas_force(x, gas_constant, width, f):
    """Add the gas force (N) to ``f`` (3, N) of a ring with nodes ``x`` (3, N) m in the x-y plane,
    counter-clockwise: ``p = C / A`` (Pa, ``A`` the polygon's area), ``p b |e|`` along each edge's
    outward normal, half to each end node."""
    n = x.shape[1]
    area = 0.0
    for i in range(n):
        j = (i + 1) % n
        area += 0.5 * (x[0, i] * x[1, j] - x[0, j] * x[1, i])
    s = 0.5 * gas_constant / area * width
    for i in range(n):
        j = (i + 1) % n
        fx = s * (x[1, j] - x[1, i])  # 0.5 p b |e| times the outward normal (e_y, -e_x) / |e|
        fy = -s * (x[0, j] - x[0, i])
        f[0, i] += fx
        f[1, i] += fy
        f[0, j] += fx
        f[1, j] += fy


@numba.njit(cache=True)
def floor_positions(x):
    """Put nodes below the floor y = 0 on it."""
    for i in range(x.shape[1]):
        if x[1, i] < 0.0:
            x[1, i] = 0.0


@numba.njit(cache=True)
def floor_velocities(x, v):
    """Remove the downward velocity of nodes on the floor (they leave it freely)."""
    for i in range(x.shape[1]):
        if x[1, i] <= 0.0 and v[1, i] < 0.0:
            v[1, i] = 0.0


@functools.cache
def _elastica_classes():
    """PyElastica's simulator class and the two custom effects (imported on first use)."""
    import elastica as ea

    class Drop(ea.BaseSystemCollection, ea.Constraints, ea.Forcing):
        pass

    class Gas(ea.NoForces):
        def __init__(self, gas_constant, width):
            super().__init__()
            self.gas_constant = gas_constant
            self.width = width

        def apply_forces(self, system, time=0.0):
            gas_force(system.position_collection, self.gas_constant, self.width, system.external_forces)

    class Floor(ea.ConstraintBase):
        def constrain_values(self, system, time):
            floor_positions(system.position_collection)

        def constrain_rates(self, system, time):
            floor_velocities(system.position_collection, system.velocity_collection)

    return ea, Drop, Gas, Floor


def elastica_ring(ea, ring, shear):
    """``CosseratRod.ring_rod`` on ``ring``'s rest circle in the x-y plane with ballenv's mass, EA
    and EI (see the module docstring); shear modulus ``shear * E / 3``."""
    b, h, rho, e = ring.width, ring.thickness, ring.density, ring.youngs_modulus
    centre = np.array([ring.position[0], ring.position[1], 0.0])
    rod = ea.CosseratRod.ring_rod(
        ring.n_nodes, centre, np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0]),
        2.0 * math.pi * ring.radius, math.sqrt(b * h / math.pi), rho,
        youngs_modulus=e, shear_modulus=shear * e / 3.0,
    )  # fmt: skip
    rod.bend_matrix[0, 0, :] = bending_stiffness(ring)  # about d1 = z: in-plane bending
    rod.mass_second_moment_of_inertia[0, 0, :] = rho * b * h**3 / 12.0 * rod.rest_lengths
    rod.inv_mass_second_moment_of_inertia[0, 0, :] = 1.0 / rod.mass_second_moment_of_inertia[0, 0, :]
    return rod


def stable_step_estimate(ring, shear):
    """Largest stable Position Verlet step (s) of the rod, ``2 / omega`` with ``omega^2 = (alpha G A
    l0 + 4 EI / l0) / J`` (the in-plane rotation of the directors against the shear spring and the
    zigzag bending mode; ``J = rho I l0``, ``alpha = 27/28``, ``G = shear * E / 3``)."""
    b, h, e = ring.width, ring.thickness, ring.youngs_modulus
    l0 = 2.0 * ring.radius * math.sin(math.pi / ring.n_nodes)
    inertia = ring.density * b * h**3 / 12.0 * l0
    omega2 = (27.0 / 28.0 * shear * e / 3.0 * b * h * l0 + 4.0 * bending_stiffness(ring) / l0) / inertia
    return 2.0 / math.sqrt(omega2)


def build_elastica(ring, shear):
    """(simulator, rod) of the drop, finalised, the rod inflated and at rest."""
    ea, drop_cls, gas_cls, floor_cls = _elastica_classes()
    sim = drop_cls()
    rod = elastica_ring(ea, ring, shear)
    sim.append(rod)
    radius = inflated_radius(ring)
    gas_constant = ring.pressure * rest_area(radius, ring.n_nodes)  # p A of the inflated polygon
    sim.add_forcing_to(rod).using(gas_cls, gas_constant=gas_constant, width=ring.width)
    sim.add_forcing_to(rod).using(ea.GravityForces, acc_gravity=np.array([0.0, -GRAVITY, 0.0]))
    sim.constrain(rod).using(floor_cls)
    sim.finalize()  # takes the rest strains and curvatures from the rest circle
    centre = np.array([[ring.position[0]], [ring.position[1]], [0.0]])
    rod.position_collection[:] = centre + (rod.position_collection - centre) * (radius / ring.radius)
    return sim, rod


def first_apex(y, v, low, g=GRAVITY):
    """First apex height (m) of a centre of mass recorded at heights ``y`` (m), vertical velocities
    ``v`` (m/s) and lowest node heights ``low`` (m): after the first record moving up with the ring
    off the floor, the last such record before the velocity turns down gives ``y + v^2 / 2g``
    (exact in flight for Position Verlet). NaN if it never turns."""
    free = (v > 0.0) & (low > 0.0)
    for i in np.flatnonzero(free[:-1] & (v[1:] <= 0.0)):
        return float(y[i] + v[i] ** 2 / (2.0 * g))
    return math.nan


def held_together(x, ring):
    """True if the nodes ``x`` (3, N) m are finite and within twice the inflated radius of their
    mean: an unstable step blows the ring apart within a few hundred steps."""
    if not np.all(np.isfinite(x)):
        return False
    centre = x.mean(axis=1, keepdims=True)
    return bool(np.max(np.linalg.norm(x - centre, axis=0)) < 2.0 * inflated_radius(ring))


def elastica_drop(ring, dt, shear, t_end=T_END, every=50):
    """Run PyElastica's drop: (wall and CPU time of the stepping loop in s, steps, first apex in m,
    whether the ring held together); the apex is NaN if it did not."""
    ea = _elastica_classes()[0]
    sim, rod = build_elastica(ring, shear)
    stepper = ea.PositionVerlet()
    n_steps = int(round(t_end / dt))
    rec = np.full((n_steps // every + 1, 3), np.nan)
    x, v = rod.position_collection, rod.velocity_collection
    t = np.float64(0.0)
    wall, cpu = time.perf_counter(), time.process_time()
    for k in range(n_steps):
        t = stepper.step(sim, t, dt)
        if k % every == 0:
            rec[k // every] = x[1].mean(), v[1].mean(), x[1].min()
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    stable = held_together(x, ring)
    apex = first_apex(rec[:, 0], rec[:, 1], rec[:, 2]) if stable else math.nan
    return wall, cpu, n_steps, apex, stable


def run_elastica(label, setting, repeats=3):
    """Result of PyElastica on the drop with ``setting`` (dt, shear): median times of ``repeats``."""
    ring = Ring(**RING)
    elastica_drop(ring, setting["dt"], setting["shear"], t_end=100 * setting["dt"])  # compile
    runs = [elastica_drop(ring, setting["dt"], setting["shear"]) for _ in range(repeats)]
    walls, cpus, steps, apexes, stable = zip(*runs, strict=True)
    note = "" if stable[-1] else "diverged: the step is above the stability limit"
    limit = stable_step_estimate(ring, setting["shear"])
    settings = f"dt={setting['dt']:.3g} (estimated limit {limit:.3g}), G={setting['shear']:g} E/3"
    wall, cpu = float(np.median(walls)), float(np.median(cpus))
    return Result("PyElastica", label, settings, steps[0], wall, cpu, apexes[-1], note=note)


# ----------------------------------------------------------------------------------------- analysis
def with_errors(results, reference_apex):
    for r in results:
        r.error = abs(r.apex - reference_apex) / reference_apex
    return results


def cheapest_within(results, tolerance):
    """The ballenv result of least CPU time whose error is at most ``tolerance``, or None (CPU time:
    on a shared machine a run's wall time also counts other jobs' time slices)."""
    ok = [r for r in results if r.code == "ballenv" and r.error <= tolerance]
    return min(ok, key=lambda r: r.cpu) if ok else None


def paired_ratio(ballenv_setting, elastica_setting, pairs=5):
    """(wall, CPU) time ratio PyElastica / ballenv, medians over ``pairs`` alternating runs."""
    walls, cpus = [], []
    for _ in range(pairs):
        peer = run_elastica(*elastica_setting, repeats=1)
        ours = run_ballenv(*ballenv_setting, repeats=1)
        walls.append(peer.wall / ours.wall)
        cpus.append(peer.cpu / ours.cpu)
    return float(np.median(walls)), float(np.median(cpus))


# ------------------------------------------------------------------------------------------- report
def _row(r):
    err = "-" if not math.isfinite(r.error) else f"{100 * r.error:.3f} %"
    apex = "-" if not math.isfinite(r.apex) else f"{r.apex:.5f}"
    note = f" ({r.note[:80]})" if r.note else ""
    times = f"{1e3 * r.wall:.1f} | {1e3 * r.cpu:.1f}"
    return f"| {r.code} | {r.label}{note} | {r.settings} | {r.steps} | {times} | {apex} | {err} |"


def report(refs, results, headline, ratio, quick, minutes, cpu_share):
    """The markdown page of benchmarks/results/peers.md; ``cpu_share`` = the process's CPU time over
    the run's wall time (near 1: the core was not shared with other jobs)."""
    ref, check = refs
    best = cheapest_within(results, ONE_PERCENT)
    as_good = cheapest_within(results, headline.error)
    lines = [
        "# Peer benchmark: ballenv and PyElastica on the 1-s drop",
        "",
        f"Generated by `python benchmarks/peers.py{' --quick' if quick else ''}` in {minutes:.1f} min "
        f"(ballenv {ballenv.__version__}, PyElastica {importlib.metadata.version('pyelastica')}; "
        f"2 shared cores, one used, CPU time / wall time of the whole run {cpu_share:.2f}; "
        "numba warm; OPENBLAS_NUM_THREADS=1; wall = median of repeats). The scene, both models and "
        "what the wall times include: the docstring of `benchmarks/peers.py`.",
        "",
        "## Reference",
        "",
        "| run | steps | wall (s) | first apex (m) | change |",
        "|---|---:|---:|---:|---:|",
        f"| ballenv {ref.label} | {ref.steps} | {ref.wall:.2f} | {ref.apex:.6f} | |",
    ]
    if check is not None:
        change = abs(check.apex - ref.apex) / ref.apex
        lines.append(
            f"| ballenv {check.label} | {check.steps} | {check.wall:.2f} | {check.apex:.6f} | {change:.1e} |"
        )
    lines += [
        "",
        "## Runs (errors: first apex against the reference)",
        "",
        "| code | setting | numerics | steps | wall (ms) | CPU (ms) | first apex (m) | error |",
        "|---|---|---|---:|---:|---:|---:|---:|",
        *[_row(r) for r in results],
        "",
        "## Matched accuracy",
        "",
        f"- PyElastica, {headline.label}: wall {1e3 * headline.wall:.0f} ms "
        f"(CPU {1e3 * headline.cpu:.0f} ms), first apex {headline.apex:.5f} m, "
        f"{100 * headline.error:.2f} % from ballenv's reference.",
    ]
    for name, r in (("within 1 %", best), ("at least as accurate as PyElastica's run", as_good)):
        if r is None:
            lines.append(f"- Cheapest ballenv run {name}: none in the sweep.")
        else:
            lines.append(
                f"- Cheapest ballenv run {name} (by CPU time): {r.label}, wall {1e3 * r.wall:.1f} ms "
                f"(CPU {1e3 * r.cpu:.1f} ms), error {100 * r.error:.3f} %: PyElastica takes "
                f"{headline.wall / r.wall:.1f}x its wall time ({headline.cpu / r.cpu:.1f}x its CPU time)."
            )
    if ratio is not None:
        lines.append(
            f"- **PyElastica / ballenv at matched accuracy: {ratio[0]:.1f}x in wall time, {ratio[1]:.1f}x in "
            f"CPU time** (medians over pairs of the two runs above taken in alternation: {best.label} and "
            "PyElastica's headline run; the quotients of the table's medians can mix in other jobs' load)."
        )
    return "\n".join(lines + model_difference(results, ref.apex)) + "\n"


def model_difference(results, reference_apex):
    """Lines on PyElastica's first apex against ballenv's reference, per shear stiffness and step."""
    rows = [r for r in results if r.code == "PyElastica" and math.isfinite(r.apex)]
    return [
        "",
        "## PyElastica's first apex against ballenv's reference",
        "",
        "Same mass, EA, EI, gas law, gravity and contact law by construction; what PyElastica adds is a "
        "shearable rod (Timoshenko, with the cross-section's rotary inertia). As its shear stiffness "
        "grows, its apex comes down to ballenv's unshearable one.",
        "",
        "| PyElastica run | numerics | first apex (m) | minus the reference |",
        "|---|---|---:|---:|",
        *[
            f"| {r.label} | {r.settings} | {r.apex:.5f} | {100 * (r.apex / reference_apex - 1):+.3f} % |"
            for r in rows
        ],
    ]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="fewer settings, coarser reference, one repeat")
    args = parser.parse_args(argv)
    if not elastica_available():
        print(f"peers.py needs PyElastica 1.0.0: {INSTALL_HINT}", file=sys.stderr)
        return 2
    start, cpu_start = time.perf_counter(), time.process_time()
    repeats = 1 if args.quick else 3
    ref_setting = QUICK_REFERENCE if args.quick else REFERENCE
    ref = run_ballenv(*ref_setting, repeats=1)
    check = None if args.quick else run_ballenv(*REFERENCE_CHECK, repeats=1)
    elastica_settings = [s for s in ELASTICA_SETTINGS if not args.quick or s[0] in QUICK_ELASTICA]
    ballenv_settings = [s for s in BALLENV_SETTINGS if not args.quick or s[0] in QUICK_BALLENV]
    results = [run_elastica(*s, repeats=repeats) for s in elastica_settings]
    results += [run_ballenv(*s, repeats=repeats) for s in ballenv_settings]
    with_errors(results, ref.apex)
    headline = results[0]
    best = cheapest_within(results, ONE_PERCENT)
    ratio = None
    if best is not None:
        setting = next(s for s in ballenv_settings if s[0] == best.label)
        ratio = paired_ratio(setting, elastica_settings[0], pairs=1 if args.quick else 5)
    wall = time.perf_counter() - start
    cpu_share = (time.process_time() - cpu_start) / wall
    text = report((ref, check), results, headline, ratio, args.quick, wall / 60, cpu_share)
    RESULTS.mkdir(exist_ok=True)
    write_text(RESULTS / "peers.md", text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
