"""Work-precision: what accuracy costs in time, per integrator, contact method, step control and node
count, on reference scenes with converged reference solutions; the fidelity presets on the Pareto front;
convergence orders in flight; restitution vs inflation pressure at several steps.

    python benchmarks/work_precision.py          # writes benchmarks/results/work_precision.md and .png
    python benchmarks/work_precision.py --quick  # a few points per curve (what the tests run)
    python benchmarks/work_precision.py --ray local  # its runs as Ray tasks (ballenv.cluster)

The ball is the env's (R = 0.12 m, E = 10 MPa, h = 2 mm, b = 2 cm, 30 kPa gauge, friction 0.5),
released at rest with its centre at 1 m:

* ``bounce``: one vertical bounce on flat ground, no damping, 0.9 s (past the first apex);
* ``slope``: one bounce on a 30 degree slope with friction 0.5, no damping, 0.9 s;
* ``bouncing``: 3 s of repeated bouncing on flat ground with the env's deformation damping (20 1/s);
* (two balls colliding once: not in the study yet; the ring-collision code landed after it.)

Each scene has a reference at very fine settings (generalized-alpha, adaptive, N = 256,
``impulse_tol`` = 1e-4 N s, dt <= 1e-3 s, ``newton_tol`` = 1e-10) whose own convergence is measured
by halving ``impulse_tol`` and the largest step and by doubling N. Error metrics against it: first-apex
height (relative), coefficient of restitution of the first bounce (normal centre-of-mass velocity
out / in, absolute), its contact duration (relative), centre-of-mass trajectory (RMS over a 1 ms grid,
m) and final centre-of-mass position (m). Cost: wall time (median of repeats, numba warm,
OPENBLAS_NUM_THREADS=1), accepted steps, Newton iterations.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import math  # noqa: E402
import pathlib  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from ballenv.cluster import check_cluster, collect, run_tasks, warm_simulator  # noqa: E402
from ballenv.files import write_text  # noqa: E402
from ballenv.physics import Ground, Ring, Scene, simulate  # noqa: E402
from ballenv.physics.build import initial_state  # noqa: E402
from ballenv.physics.presets import FIDELITY_PRESETS, with_fidelity  # noqa: E402
from ballenv.physics.simulation import SimulationError  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent  # the checkout: Ray workers import from it
RESULTS = ROOT / "benchmarks" / "results"
GRID_DT = 1e-3  # s: the grid of the centre-of-mass trajectory error, and the record interval of fixed steps
SLOPE = math.radians(30.0)
SCENES = {"bounce": 0.9, "slope": 0.9, "bouncing": 3.0}  # name -> t_end (s)
METRICS = {  # key -> (label, unit)
    "apex": ("first-apex height, relative error", ""),
    "cor": ("coefficient of restitution, absolute error", ""),
    "contact": ("first contact duration, relative error", ""),
    "com_l2": ("centre-of-mass trajectory, RMS error", "m"),
    "final": ("final centre-of-mass position error", "m"),
}
REFERENCE = dict(
    integrator="generalized_alpha", adaptive=True, dt=1e-3, impulse_tol=1e-4, newton_tol=1e-10, n_nodes=256
)


# --------------------------------------------------------------------------------------------- scenes
def ball(n_nodes=64, pressure=30e3, position=(0.0, 1.0)):
    """The env's ball (InflatedBall-v3 defaults) at rest."""
    return Ring(
        radius=0.12, n_nodes=n_nodes, youngs_modulus=10e6, thickness=2e-3, width=0.02, density=1100.0,
        pressure=pressure, position=position,
    )  # fmt: skip


def base_scene(name, n_nodes=64, pressure=30e3):
    """Physics of reference scene ``name`` (numerics at the Scene defaults)."""
    ring = ball(n_nodes, pressure)
    if name == "bounce":
        return Scene(rings=[ring], grounds=[Ground(friction=0.5)])
    if name == "slope":
        return Scene(rings=[ring], grounds=[Ground(angle=SLOPE, height=0.0, friction=0.5)])
    if name == "bouncing":
        return Scene(rings=[ring], grounds=[Ground(friction=0.5)], damping=20.0)
    raise ValueError(f"unknown scene {name!r}: one of {tuple(SCENES)}")


def configured(scene, **numerics):
    """``scene`` with numerical settings: integrator, contact, adaptive, dt, impulse_tol, newton_tol,
    n_nodes (any subset)."""
    numerics = dict(numerics)
    n = numerics.pop("n_nodes", None)
    if n is not None:
        scene = dataclasses.replace(
            scene, rings=tuple(dataclasses.replace(r, n_nodes=n) for r in scene.rings)
        )
    if "dt" in numerics and "dt_min" not in numerics:
        numerics["dt_min"] = min(scene.dt_min, numerics["dt"])
    return dataclasses.replace(scene, **numerics)


# -------------------------------------------------------------------------------------- observables
def _record_interval(scene):
    """Record every accepted step when adaptive; on the GRID_DT grid for fixed steps dividing it
    (the records then fall on steps, so recording does not change the run)."""
    if scene.adaptive:
        return None
    ratio = GRID_DT / scene.dt
    return GRID_DT if abs(ratio - round(ratio)) < 1e-9 and ratio >= 1 else None


def _hermite_com(t, c, v, grid):
    """Centre of mass (len(grid), 2) from records (t, c, v) by cubic Hermite interpolation (exact for
    the ballistic parabola)."""
    k = np.clip(np.searchsorted(t, grid, side="right") - 1, 0, len(t) - 2)
    h = t[k + 1] - t[k]
    s = ((grid - t[k]) / h)[:, None]
    s2, s3 = s * s, s * s * s
    h = h[:, None]
    return (
        (2 * s3 - 3 * s2 + 1) * c[k] + (s3 - 2 * s2 + s) * h * v[k]
        + (-2 * s3 + 3 * s2) * c[k + 1] + (s3 - s2) * h * v[k + 1]
    )  # fmt: skip


def observe(traj, t_end):
    """What the error metrics compare: first apex (m), restitution and contact duration (s) of the
    first bounce, centre of mass on the GRID_DT grid (m) and at t_end."""
    scene = traj.scene
    c = traj.centre_of_mass()[:, 0]
    v = traj.v.mean(axis=2)[:, 0]
    t = traj.t
    apexes = traj.apexes()
    first_apex = apexes[0] if len(apexes) else (math.nan, math.nan)
    touch = [e[0] for e in traj.events if e[2] == "touchdown"]
    lift = [e[0] for e in traj.events if e[2] == "liftoff" and not e[0] > first_apex[0]]
    cor = contact = math.nan
    if touch and lift:
        t_td, t_lo = touch[0], lift[-1]
        g = np.array(scene.gravity_vector)
        a = scene.grounds[0].angle
        normal = np.array([-math.sin(a), math.cos(a)])
        # in flight the centre-of-mass velocity is linear in time for both integrators: carry the
        # velocity of the nearest record in flight to the touchdown and lift-off times
        i = max(np.searchsorted(t, t_td, side="right") - 1, 0)
        j = min(np.searchsorted(t, t_lo, side="left"), len(t) - 1)
        v_in = v[i] + g * (t_td - t[i])
        v_out = v[j] - g * (t[j] - t_lo)
        cor = -float(normal @ v_out) / float(normal @ v_in)
        contact = t_lo - t_td
    grid = np.arange(0.0, t_end + 0.5 * GRID_DT, GRID_DT)
    grid[-1] = min(grid[-1], t[-1])
    return {
        "apex": float(first_apex[1]),
        "cor": cor,
        "contact": contact,
        "com": _hermite_com(t, c, v, grid),
        "final": c[-1].copy(),
    }


def errors(obs, ref):
    """The five error metrics of observation ``obs`` against the reference observation ``ref``."""
    n = min(len(obs["com"]), len(ref["com"]))
    return {
        "apex": abs(obs["apex"] - ref["apex"]) / ref["apex"],
        "cor": abs(obs["cor"] - ref["cor"]),
        "contact": abs(obs["contact"] - ref["contact"]) / ref["contact"],
        "com_l2": float(np.sqrt(np.mean(np.sum((obs["com"][:n] - ref["com"][:n]) ** 2, axis=1)))),
        "final": float(np.linalg.norm(obs["final"] - ref["final"])),
    }


@dataclasses.dataclass
class Run:
    """One measured configuration: observation, cost and its errors (filled against a reference)."""

    obs: dict
    wall: float  # s, median of repeats
    steps: int
    rejected: int
    newton: int
    errors: dict = dataclasses.field(default_factory=dict)


def run(scene, t_end, repeats=3, long_run=2.0):
    """Simulate ``scene`` (numba warm) ``repeats`` times -> Run with the median wall time; a run
    longer than ``long_run`` s is not repeated (its wall time is far above the timer noise). A run
    that raises SimulationError gives a Run with ``obs=None`` and the failure in ``errors["failed"]``."""
    simulate(scene, min(t_end, 1e-3))  # compile / load the cache for this scene's kernels
    walls = []
    for _ in range(repeats):
        try:
            traj = simulate(scene, t_end, output_dt=_record_interval(scene))
        except SimulationError as exc:
            s = exc.trajectory.stats
            failed = Run(None, s.wall_time, s.steps, s.rejected_steps, s.newton_iterations)
            failed.errors = {**dict.fromkeys(METRICS, math.nan), "failed": str(exc)}
            return failed
        walls.append(traj.stats.wall_time)
        if traj.stats.wall_time > long_run:
            break
    s = traj.stats
    return Run(observe(traj, t_end), float(np.median(walls)), s.steps, s.rejected_steps, s.newton_iterations)


def reference(name, **override):
    """Run of scene ``name`` at the reference settings (with ``override``)."""
    settings = {**REFERENCE, **override}
    return run(configured(base_scene(name), **settings), SCENES[name], repeats=1)


# ------------------------------------------------------------------------- convergence order in flight
def flight_scene(integrator, dt, n_nodes=32):
    """The ball in flight (no ground, gravity on), released 2 % squashed so it vibrates."""
    return configured(
        Scene(rings=[ball(n_nodes, position=(0.0, 0.0))]), integrator=integrator, dt=dt, adaptive=False
    )


def flight_state(integrator, dt, t_end=0.01, n_nodes=32, amplitude=2e-3):
    """Node positions (N, 2) at ``t_end`` of the ball in flight released ovalised: the inextensional
    n = 2 shape (radial ``a cos 2 theta``, tangential ``-a/2 sin 2 theta``, ``a = amplitude`` m), at rest."""
    scene = flight_scene(integrator, dt, n_nodes)
    x0, v0 = initial_state(scene)
    x = x0[0] - x0[0].mean(axis=0)
    theta = np.arctan2(x[:, 1], x[:, 0])
    radial = np.stack([np.cos(theta), np.sin(theta)], axis=1)
    tangential = np.stack([-np.sin(theta), np.cos(theta)], axis=1)
    shape = amplitude * (np.cos(2 * theta)[:, None] * radial - 0.5 * np.sin(2 * theta)[:, None] * tangential)
    traj = simulate(scene, t_end, x0=x0[0] + shape, v0=v0[0], output_dt=t_end)
    return traj.x[-1, 0], traj.v[-1, 0]


def flight_errors(integrator, dts, t_end=0.01, n_nodes=32, reference_dt=None):
    """Max node-position error (m) at ``t_end`` per step in ``dts`` against a much finer run of the
    same integrator (generalized-alpha at dt / 16 of the finest)."""
    ref_dt = reference_dt or min(dts) / 16
    ref, _ = flight_state("generalized_alpha", ref_dt, t_end, n_nodes)
    return np.array([np.max(np.abs(flight_state(integrator, dt, t_end, n_nodes)[0] - ref)) for dt in dts])


def fitted_order(dts, errs):
    """Least-squares slope of log(error) against log(dt)."""
    return float(np.polyfit(np.log(dts), np.log(errs), 1)[0])


# ------------------------------------------------------------------------------------------- sweeps
INTEGRATORS = {"generalized_alpha": "GA", "backward_euler": "BE"}
CONTACTS = {"mass_modification": "MM", "predictor_corrector": "PC"}
FIXED_DTS = [1e-3 / 2**k for k in range(5)]  # 1e-3 .. 6.25e-5 s (they divide the 1 ms record grid)
FINE_BE_DTS = [1e-3 / 2**k for k in range(5, 10)]  # single bounce only: down to 1.95e-6 s
TOLS = [2e-2, 1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4]  # N s; adaptive runs take dt <= 1e-2 s
N_SWEEP = [16, 32, 64, 128, 256]


def curves(name, quick=False):
    """{curve label: [(point label, numerics)]} for scene ``name``: one curve per integrator x contact
    x step control at N = 64; on the single bounce also finer backward-Euler steps, an N sweep and
    full tolerance sweeps at N = 32 and 128 (the candidates for the presets)."""
    dts = FIXED_DTS[1:4:2] if quick else FIXED_DTS
    tols = TOLS[2:5:2] if quick else TOLS
    out = {}
    for integrator, i in INTEGRATORS.items():
        for contact, c in CONTACTS.items():
            if quick and contact != "mass_modification":
                continue
            common = dict(integrator=integrator, contact=contact, n_nodes=64)
            fixed = dts + (FINE_BE_DTS if name == "bounce" and i == "BE" and c == "MM" and not quick else [])
            out[f"{i} {c} fixed"] = [(f"dt={dt:.3g}", dict(common, adaptive=False, dt=dt)) for dt in fixed]
            out[f"{i} {c} adaptive"] = [
                (f"tol={tol:g}", dict(common, adaptive=True, dt=1e-2, impulse_tol=tol)) for tol in tols
            ]
    if name == "bouncing" and not quick:  # does the largest step matter over many bounces?
        out["GA MM adaptive, dt <= 2e-3"] = [
            (
                f"tol={tol:g}",
                dict(integrator="generalized_alpha", n_nodes=64, adaptive=True, dt=2e-3, impulse_tol=tol),
            )
            for tol in TOLS
        ]
    if name == "bounce" and not quick:
        ga = dict(integrator="generalized_alpha", contact="mass_modification", adaptive=True, dt=1e-2)
        out["GA MM adaptive tol=5e-4, N sweep"] = [
            (f"N={n}", dict(ga, impulse_tol=5e-4, n_nodes=n)) for n in N_SWEEP
        ]
        for n in (32, 128):
            out[f"GA MM adaptive N={n}"] = [
                (f"tol={tol:g}", dict(ga, impulse_tol=tol, n_nodes=n)) for tol in TOLS
            ]
    return out


def preset_scene(name, preset):
    return with_fidelity(base_scene(name), preset)


def sweep_jobs(name, quick=False, repeats=3):
    """The runs of scene ``name``'s sweep: ``[(curve, point, scene, t_end, repeats)]``, curve by curve,
    the presets last (curve "presets", point: the preset's name)."""
    t_end = SCENES[name]
    jobs = [
        (curve, point, configured(base_scene(name), **numerics), t_end, repeats)
        for curve, points in curves(name, quick).items()
        for point, numerics in points
    ]
    return jobs + [("presets", p, preset_scene(name, p), t_end, repeats) for p in FIDELITY_PRESETS]


def sweep(points, results, ref):
    """{curve: [(point, Run)]} of a scene's sweep from its ``[(curve, point)]`` (:func:`sweep_jobs`)
    and their Runs, with errors against ``ref`` (a Run)."""
    out = {}
    for (curve, point), r in zip(points, results, strict=True):
        if r.obs is not None:
            r.errors = errors(r.obs, ref.obs)
        out.setdefault(curve, []).append((point, r))
    return out


def pareto(runs, metric="apex"):
    """The runs (curve, point, Run) no other run beats in both wall time and ``metric`` error."""
    rows = sorted(
        ((c, p, r) for c, pts in runs.items() for p, r in pts if np.isfinite(r.errors[metric])),
        key=lambda row: (row[2].wall, row[2].errors[metric]),
    )
    front, best = [], math.inf
    for row in rows:
        if row[2].errors[metric] < best:
            front.append(row)
            best = row[2].errors[metric]
    return front


# ------------------------------------------------------------------- restitution vs inflation pressure
PRESSURES = [5e3, 10e3, 20e3, 30e3, 45e3, 60e3]
COR_SETTINGS = {  # label -> numerics (N = 64, mass-modification)
    **{f"BE dt={dt:.3g}": dict(integrator="backward_euler", adaptive=False, dt=dt) for dt in FIXED_DTS[::2]},
    "BE dt=1.56e-05": dict(integrator="backward_euler", adaptive=False, dt=1e-3 / 64),
    "GA dt=1e-3": dict(integrator="generalized_alpha", adaptive=False, dt=1e-3),
    "GA adaptive tol=1e-4 (converged)": dict(
        integrator="generalized_alpha", adaptive=True, dt=1e-3, impulse_tol=1e-4, newton_tol=1e-10
    ),
}


def restitution(pressure, numerics, t_end=0.5):
    """Coefficient of restitution of the first bounce of the single-bounce scene at ``pressure`` (Pa)."""
    scene = configured(base_scene("bounce", 64, pressure), **numerics)
    try:
        traj = simulate(scene, t_end, output_dt=_record_interval(scene))
    except SimulationError:
        return math.nan
    return observe(traj, t_end)["cor"]


# ------------------------------------------------------------- damping of the wall's vibration in flight
DECAY_DTS = [1e-2, 5e-3, 2e-3, 5e-4, 1e-4]


def vibration_decay(dt_max, impulse_tol=1e-3, window=(0.55, 1.05), t_end=1.5):
    """Damped 3 s scene (c = 20 1/s), GA adaptive with largest step ``dt_max``: the decay rate (1/s) of
    the wall's vibration energy in the first flight, ``ln(E(t0) / E(t1)) / (t1 - t0)`` over ``window``,
    and the second apex (m). Vibration energy: kinetic + elastic + gas energy minus the rest state's
    and the centre of mass's kinetic energy (it does not oscillate within a period, so sparse records
    do not alias it). A lightly damped mode of ``u'' + c u' + w^2 u = 0`` loses energy at the rate c."""
    scene = configured(base_scene("bouncing"), n_nodes=64, adaptive=True, dt=dt_max, impulse_tol=impulse_tol)
    traj = simulate(scene, t_end)
    e = traj.energy()
    internal = e["kinetic"][:, 0] + e["stretching"][:, 0] + e["bending"][:, 0] + e["gas"][:, 0]
    v_cm = traj.v[:, 0].mean(axis=1)
    mass = _ring_mass(scene)
    internal = internal - internal[0] - 0.5 * mass * np.sum(v_cm**2, axis=1)
    k0, k1 = (np.searchsorted(traj.t, t) for t in window)
    rate = math.log(internal[k0] / internal[k1]) / (traj.t[k1] - traj.t[k0])
    apexes = traj.apexes()
    return rate, float(apexes[1, 1]) if len(apexes) > 1 else math.nan


def _ring_mass(scene):
    from ballenv.physics.base.ring import node_mass

    ring = scene.rings[0]
    return node_mass(ring) * ring.n_nodes


# ---------------------------------------------------------------------------------------------- main
REFERENCE_CHECKS = {  # label -> override of the reference settings
    "impulse_tol and dt halved": dict(impulse_tol=REFERENCE["impulse_tol"] / 2, dt=REFERENCE["dt"] / 2),
    "N doubled (512)": dict(n_nodes=2 * REFERENCE["n_nodes"]),
}
# where halving the tolerance fails (SimulationError), the finer-step check is a fixed step instead
FALLBACK_CHECK = ("fixed dt = 2e-5 s (tolerance halving failed)", dict(adaptive=False, dt=2e-5))


def _fmt(x, spec=".1e"):
    return "-" if x is None or not np.isfinite(x) else format(x, spec)


def reference_check(name, label):
    """``(label, Run)`` of reference check ``label`` of scene ``name`` (REFERENCE_CHECKS), or of
    FALLBACK_CHECK if that run fails."""
    r = reference(name, **REFERENCE_CHECKS[label])
    if r.obs is None:
        label, override = FALLBACK_CHECK
        r = reference(name, **override)
    return label, r


def references(ref_runs, check_runs):
    """{scene: (reference Run, {check label: (Run, errors vs reference)}, uncertainty per metric)}
    from the reference runs {scene: Run} and the checks' runs {scene: [(label, Run)]}."""
    out = {}
    for name, ref in ref_runs.items():
        checks = {
            label: (r, errors(r.obs, ref.obs) if r.obs is not None else None) for label, r in check_runs[name]
        }
        unc = {m: max(e[m] for _, e in checks.values() if e is not None) for m in METRICS} if checks else {}
        out[name] = (ref, checks, unc)
    return out


def balanced_vs_backward_euler(bounce_runs):
    """The target: balanced preset within 1 % of the converged first apex and >= 10x cheaper than the
    cheapest fixed-step backward-Euler run at least as accurate. Returns a dict of the numbers."""
    balanced = dict(bounce_runs["presets"])["balanced"]
    err = balanced.errors["apex"]
    fixed = bounce_runs["BE MM fixed"] + bounce_runs.get("BE PC fixed", [])
    be = [(p, r) for p, r in fixed if r.obs is not None]
    as_good = [(p, r) for p, r in be if r.errors["apex"] <= err]
    one_percent = [(p, r) for p, r in be if r.errors["apex"] <= 0.01]
    cheapest = min(as_good, key=lambda pr: pr[1].wall) if as_good else None
    cheapest_1 = min(one_percent, key=lambda pr: pr[1].wall) if one_percent else None
    best_be = min(be, key=lambda pr: pr[1].errors["apex"])
    return {
        "balanced_error": err,
        "balanced_wall": balanced.wall,
        "be_as_good": cheapest,
        "be_1pct": cheapest_1,
        "be_best": best_be,
    }


def study_jobs(quick):
    """Every run of the study, each independent of the others: ``[(key, function, args)]``."""
    names = ["bounce"] if quick else list(SCENES)
    jobs = [(("reference", name), reference, (name,)) for name in names]
    if not quick:
        jobs += [
            (("check", name), reference_check, (name, label)) for name in names for label in REFERENCE_CHECKS
        ]
    for name in names:
        jobs += [
            (("sweep", name, curve, point), run, rest) for curve, point, *rest in sweep_jobs(name, quick)
        ]
    jobs += [(("flight", i), flight_order, (i,)) for i in INTEGRATORS]
    if not quick:
        jobs += [(("decay", dt), vibration_decay, (dt,)) for dt in DECAY_DTS]
        jobs += [
            (("cor", label), restitution, (p, COR_SETTINGS[label]))
            for label in COR_SETTINGS
            for p in PRESSURES
        ]
    return names, jobs


def call(job):
    """The result of one job of :func:`study_jobs` (a Ray task's function: one argument)."""
    _, function, args = job
    return function(*args)


def flight_order(integrator):
    """``(dts, errors, fitted order)`` of ``integrator`` in flight."""
    dts = np.array([1e-4, 5e-5, 2.5e-5, 1.25e-5])
    errs = flight_errors(integrator, dts)
    return dts, errs, fitted_order(dts, errs)


def assemble(names, jobs, results, quick):
    """The study's tables (references, sweeps, orders, restitution, decay) from its jobs' results."""
    by_key = {}
    for (key, *_), result in zip(jobs, results, strict=True):
        by_key.setdefault(key[:2], []).append(result)
    ref_runs = {name: by_key[("reference", name)][0] for name in names}
    refs = references(ref_runs, {name: by_key.get(("check", name), []) for name in names})
    points = {name: [key[2:] for key, *_ in jobs if key[:2] == ("sweep", name)] for name in names}
    runs = {name: sweep(points[name], by_key[("sweep", name)], ref_runs[name]) for name in names}
    orders = {i: by_key[("flight", i)][0] for i in INTEGRATORS}
    decay = {dt: by_key[("decay", dt)][0] for dt in DECAY_DTS} if not quick else {}
    cor = {label: by_key[("cor", label)] for label in COR_SETTINGS} if not quick else {}
    return refs, runs, orders, cor, decay


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="a few points per curve, single bounce only")
    parser.add_argument(
        "--ray",
        dest="cluster",
        metavar="ADDRESS",
        default=None,
        help="run the study's runs as Ray tasks: 'local' (a cluster on this machine), 'auto' or an address",
    )
    args = parser.parse_args(argv)
    RESULTS.mkdir(exist_ok=True)
    names, jobs = study_jobs(args.quick)
    start = time.perf_counter()
    outcomes = run_tasks(
        call, jobs, check_cluster(args.cluster), desc="work-precision", warm=warm_simulator, paths=[str(ROOT)]
    )
    results, lost = collect(outcomes, len(jobs))
    if lost:
        raise SystemExit(f"runs lost with their Ray worker after Ray's retries: {[t.index for t in lost]}")
    elapsed = time.perf_counter() - start
    refs, runs, orders, cor, decay = assemble(names, jobs, results, args.quick)
    text = report(refs, runs, orders, cor, decay, elapsed, args.quick, args.cluster)
    suffix = "_quick" if args.quick else ""
    write_text(RESULTS / f"work_precision{suffix}.md", text)
    print(text)
    plot_sweeps(refs, runs, RESULTS / f"work_precision{suffix}.png")
    plot_extras(runs["bounce"], refs["bounce"], orders, cor, RESULTS / f"work_precision_pareto{suffix}.png")


def report(refs, runs, orders, cor, decay, elapsed, quick, cluster=None):
    lines = [
        "# Work-precision",
        "",
        f"Generated by `python benchmarks/work_precision.py{' --quick' if quick else ''}` in "
        f"{elapsed / 60:.1f} min ("
        + (
            f"as Ray tasks on {cluster}, each run's wall time taken beside the other workers; "
            if cluster
            else ""
        )
        + "2 cores, numba warm, OPENBLAS_NUM_THREADS=1; wall time = median of 3 "
        "repeats, 1 for runs over 2 s). N = 64 and mass-modification contact unless a row says otherwise; "
        "adaptive runs take dt <= 1e-2 s. Errors against the scene's reference. GA = generalized-alpha "
        "(rho_infinity 0.9), BE = backward Euler, MM / PC = mass-modification / predictor-corrector.",
        "",
        "Metrics: `apex` first-apex height (relative), `COR` restitution of the first bounce "
        "(absolute), `contact` its duration (relative), `CoM L2` RMS centre-of-mass error over time "
        "(m, 1 ms grid), `final` centre-of-mass position at the end (m).",
        "",
        "## References and their own convergence",
        "",
        "Reference: generalized-alpha, adaptive, N = 256, impulse_tol = 1e-4 N s, dt <= 1e-3 s, "
        "newton_tol = 1e-10. Rows below the reference: the change of each metric when the reference's "
        "step control is refined or its N doubled; the larger change is the reference's uncertainty, "
        "shaded grey in the plots (errors inside it are not resolved).",
        "",
        "| scene | run | apex (m) | COR | contact (ms) | steps | wall (s) | d apex | d COR | d contact "
        "| d CoM L2 (m) | d final (m) |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name, (ref, checks, _) in refs.items():
        o = ref.obs
        lines.append(
            f"| {name} | reference | {o['apex']:.5f} | {o['cor']:.4f} | {o['contact'] * 1e3:.3f} "
            f"| {ref.steps} | {ref.wall:.1f} | | | | | |"
        )
        for label, (r, e) in checks.items():
            if e is None:
                lines.append(f"| {name} | {label} | failed | | | {r.steps} | {r.wall:.1f} | | | | | |")
                continue
            o = r.obs
            lines.append(
                f"| {name} | {label} | {o['apex']:.5f} | {o['cor']:.4f} | {o['contact'] * 1e3:.3f} "
                f"| {r.steps} | {r.wall:.1f} | " + " | ".join(_fmt(e[m]) for m in METRICS) + " |"
            )
    for name, scene_runs in runs.items():
        lines += [
            "",
            f"## Scene `{name}` ({SCENES[name]:g} s)",
            "",
            "| method | setting | steps | rejected | Newton | wall (ms) | apex | COR | contact | CoM L2 (m) "
            "| final (m) |",
            "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
        ]
        for curve, points in scene_runs.items():
            for point, r in points:
                tail = (
                    " | ".join(_fmt(r.errors[m]) for m in METRICS)
                    if r.obs is not None
                    else "failed: " + r.errors["failed"].split(";")[0] + " | | | |"
                )
                cost = f"{r.steps} | {r.rejected} | {r.newton} | {r.wall * 1e3:.1f}"
                lines.append(f"| {curve} | {point} | {cost} | {tail} |")
    bounce = runs["bounce"]
    lines += [
        "",
        "## Pareto front: single bounce, first-apex error against wall time",
        "",
        "Every run above (all methods, N, presets) that no other run beats in both wall time and "
        "first-apex error, cheapest first:",
        "",
        "| method | setting | wall (ms) | steps | Newton | apex error |",
        "|---|---|---:|---:|---:|---:|",
    ]
    for curve, point, r in pareto(bounce):
        lines.append(
            f"| {curve} | {point} | {r.wall * 1e3:.1f} | {r.steps} | {r.newton} | {r.errors['apex']:.1e} |"
        )
    lines += [
        "",
        "## Fidelity presets",
        "",
        "| preset | " + " | ".join(f"{n}: apex err, wall (ms)" for n in runs) + " |",
        "|---|" + "---:|" * len(runs),
    ]
    for preset in FIDELITY_PRESETS:
        cells = []
        for scene_runs in runs.values():
            r = dict(scene_runs["presets"])[preset]
            cells.append(f"{_fmt(r.errors['apex'])}, {r.wall * 1e3:.1f}")
        lines.append(f"| {preset} | " + " | ".join(cells) + " |")
    t = balanced_vs_backward_euler(bounce)
    lines += ["", "## Target: balanced preset vs fixed-step backward Euler (single bounce)", ""]
    lines.append(
        f"* balanced: first-apex error {t['balanced_error']:.2e} (target <= 1e-2: "
        f"{'met' if t['balanced_error'] <= 0.01 else 'missed'}), {t['balanced_wall'] * 1e3:.1f} ms."
    )
    for key, what in (("be_as_good", "as accurate as balanced"), ("be_1pct", "within 1 %")):
        if t[key] is None:
            lines.append(f"* no fixed-step backward-Euler run is {what}.")
        else:
            p, r = t[key]
            ratio = r.wall / t["balanced_wall"]
            lines.append(
                f"* cheapest fixed-step backward Euler {what}: {p}, error {r.errors['apex']:.2e}, "
                f"{r.wall * 1e3:.0f} ms = {ratio:.0f}x the balanced preset (target >= 10x: "
                f"{'met' if ratio >= 10 else 'missed'})."
            )
    p, r = t["be_best"]
    lines.append(
        f"* most accurate fixed-step backward Euler run: {p}, error {r.errors['apex']:.2e}, "
        f"{r.wall * 1e3:.0f} ms ({r.wall / t['balanced_wall']:.0f}x the balanced preset)."
    )
    lines += [
        "",
        "## Convergence order in flight",
        "",
        "The ball in flight (no ground, gravity on, N = 32), released at rest ovalised by 2 mm in the "
        "inextensional n = 2 shape, 10 ms: max node-position error against generalized-alpha at "
        "dt / 16 of the finest step.",
        "",
        "| integrator | "
        + " | ".join(f"dt = {dt:.3g}" for dt in next(iter(orders.values()))[0])
        + " | fitted order |",
        "|---|" + "---:|" * (len(next(iter(orders.values()))[0]) + 1),
    ]
    for integrator, (_, errs, order) in orders.items():
        lines.append(f"| {integrator} | " + " | ".join(f"{e:.2e}" for e in errs) + f" | {order:.2f} |")
    if cor:
        lines += [
            "",
            "## Restitution vs inflation pressure at several steps",
            "",
            "Coefficient of restitution of the first bounce of the single-bounce scene (N = 64, "
            "mass-modification) vs the gauge pressure:",
            "",
            "| settings | " + " | ".join(f"{p / 1e3:g} kPa" for p in PRESSURES) + " |",
            "|---|" + "---:|" * len(PRESSURES),
        ]
        for label, values in cor.items():
            lines.append(f"| {label} | " + " | ".join(_fmt(v, ".3f") for v in values) + " |")
    if decay:
        lines += [
            "",
            "## Damping of the wall's vibration in flight vs the largest step",
            "",
            "3 s scene (damping c = 20 1/s), GA adaptive, impulse_tol = 1e-3 N s, N = 64: decay rate of the "
            "vibration energy in the first flight (physical: about c = 20 1/s) and the second apex:",
            "",
            "| largest dt (s) | " + " | ".join(f"{dt:g}" for dt in decay) + " |",
            "|---|" + "---:|" * len(decay),
            "| decay rate (1/s) | " + " | ".join(f"{r:.1f}" for r, _ in decay.values()) + " |",
            "| second apex (m) | " + " | ".join(f"{a:.4f}" for _, a in decay.values()) + " |",
        ]
    return "\n".join(lines) + "\n"


def _style(curve):
    color = {"GA": "tab:blue", "BE": "tab:red"}[curve[:2]]
    if "N=32" in curve:
        color = "tab:cyan"
    elif "N=128" in curve:
        color = "tab:purple"
    elif "N sweep" in curve:
        color = "tab:green"
    elif "2e-3" in curve:
        color = "tab:olive"
    ls = "-" if "adaptive" in curve else "--"
    marker = "o" if " MM " in curve else "s"
    return dict(color=color, ls=ls, marker=marker, ms=3, lw=1)


def _shade_below(ax, level, **kw):
    """Grey band from the bottom of the data up to ``level`` (the reference's own uncertainty)."""
    lo, hi = ax.get_ylim()
    lo = min(lo, 0.5 * level)
    ax.axhspan(lo, level, color="0.85", zorder=0, **kw)
    ax.set_ylim(lo, max(hi, 2 * level))


def plot_sweeps(refs, runs, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(
        len(runs), len(METRICS), figsize=(4 * len(METRICS), 3.3 * len(runs)), squeeze=False
    )
    for row, (name, scene_runs) in zip(axes, runs.items(), strict=True):
        unc = refs[name][2]
        for ax, (metric, (label, unit)) in zip(row, METRICS.items(), strict=True):
            for curve, points in scene_runs.items():
                pts = [(r.wall, r.errors[metric]) for _, r in points if r.obs is not None]
                pts = [(w, max(e, 1e-7)) for w, e in pts if np.isfinite(e)]
                if not pts:
                    continue
                w, e = zip(*pts, strict=True)
                if curve == "presets":
                    ax.scatter(w, e, marker="*", s=120, color="gold", edgecolor="k", zorder=5, label=curve)
                    for p, r in points:
                        if r.obs is not None and np.isfinite(r.errors[metric]):
                            ax.annotate(p, (r.wall, max(r.errors[metric], 1e-7)), fontsize=6)
                else:
                    ax.loglog(w, e, label=curve, **_style(curve))
            ax.set_xscale("log")
            ax.set_yscale("log")
            if metric in unc:
                _shade_below(ax, unc[metric])
            ax.set_title(f"{name}: {label}", fontsize=8)
            ax.set_xlabel("wall time (s)", fontsize=8)
            ax.set_ylabel(f"error{f' ({unit})' if unit else ''}", fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(True, which="major", lw=0.3)
    axes[0, 0].legend(fontsize=6, ncol=1)
    for row in axes[1:]:  # curves of this row that the first row's legend does not list
        first = set(axes[0, 0].get_legend_handles_labels()[1])
        handles = [
            (h, lab) for h, lab in zip(*row[0].get_legend_handles_labels(), strict=True) if lab not in first
        ]
        if handles:
            row[0].legend(*zip(*handles, strict=True), fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path}")


def plot_extras(bounce_runs, bounce_ref, orders, cor, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3 if cor else 2, figsize=(15 if cor else 10, 4.2))
    ax = axes[0]
    for curve, points in bounce_runs.items():
        pts = [(r.wall, r.errors["apex"]) for _, r in points if r.obs is not None]
        if pts and curve != "presets":
            w, e = zip(*pts, strict=True)
            ax.scatter(w, e, s=8, alpha=0.5, **{k: v for k, v in _style(curve).items() if k == "color"})
    front = pareto(bounce_runs)
    ax.loglog(
        [r.wall for _, _, r in front],
        [r.errors["apex"] for _, _, r in front],
        "k-",
        lw=1.2,
        label="Pareto front",
    )
    for preset, r in bounce_runs["presets"]:
        ax.scatter([r.wall], [r.errors["apex"]], marker="*", s=160, color="gold", edgecolor="k", zorder=5)
        ax.annotate(preset, (r.wall, r.errors["apex"]), fontsize=8)
    ax.axhline(0.01, color="k", ls=":", lw=0.8, label="1 %")
    ax.set_xscale("log")
    ax.set_yscale("log")
    if bounce_ref[2]:
        _shade_below(ax, bounce_ref[2]["apex"], label="reference uncertainty")
    ax.set_xlabel("wall time (s)")
    ax.set_ylabel("first-apex relative error")
    ax.set_title("single bounce: every run (blue GA, red BE), presets, front", fontsize=9)
    ax.legend(fontsize=7)
    ax = axes[1]
    for integrator, (dts, errs, order) in orders.items():
        ax.loglog(dts, errs, "o-", label=f"{INTEGRATORS[integrator]}: fitted order {order:.2f}")
    dts = next(iter(orders.values()))[0]
    for k, ls in ((1, ":"), (2, "--")):
        e0 = list(orders.values())[k - 1][1][0]
        ax.loglog(dts, e0 * (dts / dts[0]) ** k, "k", ls=ls, lw=0.7, label=f"slope {k}")
    ax.set_xlabel("dt (s)")
    ax.set_ylabel("max node-position error at 10 ms (m)")
    ax.set_title("flight (no contact): convergence order", fontsize=9)
    ax.legend(fontsize=7)
    if cor:
        ax = axes[2]
        for label, values in cor.items():
            ax.plot(np.array(PRESSURES) / 1e3, values, "o-" if "BE" in label else "s-", label=label, ms=4)
        ax.set_xlabel("gauge pressure (kPa)")
        ax.set_ylabel("coefficient of restitution, first bounce")
        ax.set_title("restitution vs inflation: where BE's damping hides the trend", fontsize=9)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
