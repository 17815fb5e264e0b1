"""Soak run of the stability suite (``tests/stability``): thousands of random scenes and env episodes, seeded.

    python benchmarks/soak.py [--scenes 2000] [--episodes 400] [--seed 0] [--ray local|auto|ADDRESS]
                              [--rtol RTOL --out benchmarks/results/soak_rtol.md]
    # prints the table, writes benchmarks/results/soak.md

Scenes: drawn like ``tests/stability/test_random.py``'s valid scenes (the hard cases' ranges): one
or two rings of radius 0.05-0.3 m, N 8-256, E 0.1 MPa-1 GPa (log-uniform), h/R 0.005-0.3, gauge
pressure none or 0-40 % of the wall's bound (at most 10 bar), released 1 mm-0.5 m above a floor or a
slope of up to 75 degrees (friction 0-2) at up to 30 m/s per component and 50 rad/s, gravity
0-20 m/s^2, damping 0/5/50 1/s, either contact method and integrator, rho_inf 0-1, adaptive or
fixed steps of 1e-4-1e-2 s (adaptive: the contact impulse per step at most 5e-3 N s, or with
``--rtol`` the error control ``Scene.rtol``), 0.02-0.15 s simulated. Each run is audited
(``tests/stability/invariants.py``): non-finite states, tunnelling (a node more than 1e-6 m below a
ground, or inside another ring), energy growth (total energy above its start value by more than
1e-9 of the start's sum of |parts| plus the energy the collision impulses' push-out created), and
how it ended (t_end, a documented SimulationError by reason, or anything else).

Episodes: InflatedBall-v3 (fast preset), both action modes, 250 steps each (2.5 s) of uniform
random, extreme (+1 / -1) or alternating-extreme actions, resets included: non-finite or
out-of-bounds observations, nodes below the ground, simulator failures.

``--ray`` runs the scenes as Ray tasks (``ballenv.cluster``: 'local' starts a cluster on this
machine; 'auto' or an address joins a running one) with the same tallies as the serial run, each
node's numba cache warmed first; a scene whose worker died is retried, and one lost after Ray's
retries is listed in the report and left out of the tallies. The episodes stay in this process
(they draw from one random stream).
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import math  # noqa: E402
import pathlib  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import traceback  # noqa: E402
from collections import Counter  # noqa: E402
from dataclasses import dataclass, replace  # noqa: E402
from functools import partial  # noqa: E402
from typing import NamedTuple  # noqa: E402

import numpy as np  # noqa: E402
from tqdm.auto import tqdm  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from ballenv.cluster import check_cluster, collect, run_tasks, warm_simulator  # noqa: E402
from ballenv.envs.inflated_ball import InflatedBallEnv  # noqa: E402
from ballenv.files import write_text  # noqa: E402
from ballenv.physics import Ground, Ring, Scene  # noqa: E402
from ballenv.physics.base.ring import inflated_radius  # noqa: E402
from tests.stability.invariants import (  # noqa: E402
    ENERGY_ROUND_OFF,
    GROUND_TOLERANCE,
    audit,
)

RESULTS = ROOT / "benchmarks" / "results"
REASONS = ("newton", "energy", "intrusion", "self_intersection", "impulse", "error")
FAILURE_KEYS = {
    "a ring's wall crossed itself": "dt_min: wall crossed itself",
    "Newton's iteration did not converge": "dt_min: Newton did not converge",
    "the step gained energy": "dt_min: step gained energy",
    "a node of one ring ended inside another ring": "dt_min: ring intrusion",
    "contact impulse per step stayed above": "impulse above impulse_tol at dt_min",
    "contact impulse per step or the local error stayed above": "impulse or local error above rtol at dt_min",
}


def log_uniform(rng, lo, hi):
    return math.exp(rng.uniform(math.log(lo), math.log(hi)))


def random_scene(rng):
    """A random valid scene in the hard cases' ranges and its end time (see the module doc)."""
    radius = rng.uniform(0.05, 0.3)
    modulus = log_uniform(rng, 1e5, 1e9)
    thickness = radius * log_uniform(rng, 0.005, 0.3)
    burst = 0.5 * modulus * thickness / radius
    pressure = None if rng.random() < 0.15 else rng.uniform(0.0, min(1e6, 0.4 * burst))
    n_nodes = int(rng.choice([8, 16, 32, 64, 128, 256], p=[0.1, 0.25, 0.3, 0.2, 0.1, 0.05]))
    angle = math.radians(rng.uniform(-75.0, 75.0) if rng.random() < 0.6 else 0.0)
    normal = np.array([-math.sin(angle), math.cos(angle)])
    tangent = np.array([normal[1], -normal[0]])
    base = Ring(
        radius=radius, n_nodes=n_nodes, youngs_modulus=modulus, thickness=thickness,
        width=rng.uniform(0.005, 0.1), density=rng.uniform(100.0, 3000.0), pressure=pressure,
    )  # fmt: skip
    lift = inflated_radius(base) + rng.uniform(1e-3, 0.5)
    rings = []
    for k in range(1 if rng.random() < 0.75 else 2):
        centre = lift * normal + 3.0 * lift * k * tangent
        rings.append(
            replace(base, position=tuple(centre), velocity=tuple(rng.uniform(-30.0, 30.0, 2)),
                    angular_velocity=rng.uniform(-50.0, 50.0))
        )  # fmt: skip
    scene = Scene(
        rings=rings,
        grounds=[Ground(angle=angle, friction=rng.uniform(0.0, 2.0))],
        contact=str(rng.choice(["mass_modification", "predictor_corrector"])),
        integrator=str(rng.choice(["backward_euler", "generalized_alpha"])),
        rho_infinity=rng.uniform(0.0, 1.0),
        gravity=rng.uniform(0.0, 20.0),
        damping=float(rng.choice([0.0, 5.0, 50.0])),
        gas_exponent=float(rng.choice([1.0, 1.4])),
        atmospheric_pressure=float(rng.choice([0.0, 101325.0])),
        adaptive=bool(rng.random() < 0.7),
        dt=log_uniform(rng, 1e-4, 1e-2),
        impulse_tol=5e-3,  # adaptive steps follow the contact impulse, unless draw_scenes is given rtol
    )
    return scene, rng.uniform(0.02, 0.15)


@dataclass(frozen=True)
class SceneOutcome:
    """What the soak keeps of one scene's run: its audit without the trajectory (so that it pickles
    small from a Ray worker), the time reached and the step counts the report needs; or the crash."""

    audit: object = None  # tests.stability.invariants.Audit, traj dropped
    t_reached: float = 0.0
    energy_projected: int = 0
    newton_rescues: int = 0
    crash: str = ""
    where: tuple = ()
    seconds: float = 0.0  # wall time of the run in the process that ran it


def run_scene(task):
    """The soak's run of one ``(scene, t_end)`` task: :func:`audit`, or the crash if it raised
    anything but a documented SimulationError (a failure to report, not to stop the sweep on)."""
    scene, t_end = task
    start = time.perf_counter()
    try:
        result = audit(scene, t_end)
    except Exception as exc:
        where = tuple(traceback.format_exc().strip().splitlines()[-3:])
        return SceneOutcome(crash=f"{type(exc).__name__}: {exc}", where=where)
    stats = result.traj.stats
    return SceneOutcome(
        audit=replace(result, traj=None),
        t_reached=float(result.traj.t[-1]),
        energy_projected=stats.energy_projected,
        newton_rescues=stats.newton_rescues,
        seconds=time.perf_counter() - start,
    )


def scene_times(outcomes, cores=(1, 2, 64)):
    """Lines of the report on the scenes' run times: their sum, the longest, and the least wall time
    the scenes can take on each number of ``cores`` (one scene runs on one core):
    ``max(sum / cores, longest)``."""
    times = {index: o.seconds for index, o in enumerate(outcomes) if o is not None}  # lost: left out
    longest = sorted(times, key=lambda i: -times[i])[:5]
    total = sum(times.values())
    least = ", ".join(
        f"{c} core{'s' if c > 1 else ''} {max(total / c, times[longest[0]]) / 60:.1f} min" for c in cores
    )
    return [
        f"Run time of the scenes (each in the process that ran it): {total / 60:.1f} min in all, median "
        f"{1e3 * float(np.median(list(times.values()))):.0f} ms, longest "
        + ", ".join(f"{times[i]:.1f} s (scene {i})" for i in longest)
        + f". Least wall time of the scenes on a cluster, from these times: {least}.",
        "",
    ]


def draw_scenes(count, seed, rtol=None):
    """The soak's ``count`` random ``(scene, t_end)`` tasks of ``seed``, drawn in order; with ``rtol``
    the adaptive ones under error control (``Scene.rtol``) instead of the contact impulse bound."""
    rng = np.random.default_rng(seed)
    tasks = [random_scene(rng) for _ in range(count)]
    if rtol is None:
        return tasks
    return [(replace(s, impulse_tol=None, rtol=rtol) if s.adaptive else s, t_end) for s, t_end in tasks]


def soak_scenes(count, seed, cluster=None, rtol=None):
    """Run the soak's scenes (in this process, or as Ray tasks on ``cluster``: ballenv.cluster) and
    tally them in scene order, so the tallies do not depend on where or in which order they ran:
    ``(SceneTallies, the tasks lost with their worker, the report's lines on the run times)``."""
    tasks = draw_scenes(count, seed, rtol)
    outcomes, lost = collect(
        run_tasks(
            run_scene, tasks, cluster, desc="scenes", warm=partial(warm_simulator, audit), paths=[str(ROOT)]
        ),
        count,
    )
    return tally_scenes(tasks, outcomes), lost, scene_times(outcomes)


class SceneTallies(NamedTuple):
    """The report's tallies of the scenes: counts (``tally``), rejected steps by reason, how the
    runs ended, energy growth and the energy the budget removed per integrator, the largest rises,
    the crashes, the stops and the scenes with a node below a ground or inside another ring."""

    tally: Counter
    rejected: Counter
    ends: Counter
    growth: dict
    removed: dict
    worst: list
    crashes: list
    stops: list
    tunnelled: list


def tally_scenes(tasks, outcomes):
    """The :class:`SceneTallies` of the scenes' outcomes (None: a task lost with its worker)."""
    tally = Counter()
    rejected = Counter()
    ends = Counter()
    growth = {"backward_euler": [], "generalized_alpha": []}
    removed = {"backward_euler": [], "generalized_alpha": []}
    worst = []
    crashes = []
    stops = []
    tunnelled = []
    for index, ((scene, t_end), outcome) in enumerate(zip(tasks, outcomes, strict=True)):
        if outcome is None:
            continue
        tally["cases"] += 1
        tally[scene.integrator] += 1
        if outcome.crash:
            ends[f"crash: {outcome.crash}"[:120]] += 1
            crashes.append((index, scene, t_end, outcome.where))
            tqdm.write(f"crash in scene {index} (t_end {t_end}): {scene}\n" + "\n".join(outcome.where))
            continue
        result = outcome.audit
        tally["steps"] += result.steps
        rejected.update({k: result.rejections[k] for k in REASONS})
        tally["non-finite"] += not result.finite
        if result.penetration > GROUND_TOLERANCE or result.intrusion > 0.0:
            tally["tunnelling"] += 1
            tunnelled.append((index, result.penetration, result.intrusion))
        tally["deepest"] = max(tally["deepest"], result.penetration)
        above_start = result.energy_growth > ENERGY_ROUND_OFF
        grew = result.energy_growth > ENERGY_ROUND_OFF + result.collision_gain
        tally["energy growth"] += grew
        tally[f"energy growth {scene.integrator}"] += grew
        tally["push-out above start"] += above_start and not grew
        tally["projected runs"] += outcome.energy_projected > 0
        tally["projected steps"] += outcome.energy_projected
        tally["rescued runs"] += outcome.newton_rescues > 0
        tally["rescued steps"] += outcome.newton_rescues
        if result.finite:
            growth[scene.integrator].append(result.energy_growth)
            removed[scene.integrator].append(result.energy_removed)
        if above_start:
            worst.append((result.energy_growth, result.collision_gain, scene, t_end))
        if result.reached_end:
            ends["reached t_end"] += 1
        else:
            key = next((v for k, v in FAILURE_KEYS.items() if k in result.error), None)
            ends[key if key and result.documented else f"undocumented: {result.error[:80]}"] += 1
            stops.append((index, key or result.error[:80], outcome.t_reached, t_end, scene))
    worst.sort(key=lambda w: -w[0])
    return SceneTallies(tally, rejected, ends, growth, removed, worst, crashes, stops, tunnelled)


POLICIES = ("uniform", "plus", "minus", "alternating")


def episode_action(policy, rng, step):
    """The action of ``policy`` at ``step``: uniform in [-1, 1], +1, -1, or alternating -1 / +1 (a
    uniform number is drawn from ``rng`` at every step whatever the policy)."""
    return {
        "uniform": rng.uniform(-1.0, 1.0),
        "plus": 1.0,
        "minus": -1.0,
        "alternating": 1.0 if step % 2 else -1.0,
    }[policy]


def soak_episodes(count, seed, steps=250):
    rng = np.random.default_rng(seed)
    tally = Counter()
    envs = {mode: InflatedBallEnv(action_mode=mode) for mode in ("pressure", "paddle")}
    for k in tqdm(range(count), desc="episodes", unit="ep"):
        mode = ("pressure", "paddle")[k % 2]
        policy = POLICIES[(k // 2) % 4]
        env = envs[mode]
        env.reset(seed=int(rng.integers(2**31)))
        tally["episodes"] += 1
        for s in range(steps):
            a = episode_action(policy, rng, s)
            obs, reward, terminated, truncated, info = env.step(np.array([a], dtype=np.float32))
            tally["env steps"] += 1
            x = env._batch.state.x[0]
            tally["non-finite"] += not (
                np.all(np.isfinite(obs)) and math.isfinite(reward) and np.all(np.isfinite(x))
            )
            tally["out of bounds"] += not env.observation_space.contains(obs)
            tally["below ground"] += x[:, 1].min() < -GROUND_TOLERANCE
            if info["sim_failure"]:
                tally[f"sim failure: {info['sim_failure_reason']}"] += 1
            if terminated:
                tally[f"ended: {info['termination']}"] += 1
                env.reset()
    return tally


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=2000)
    parser.add_argument("--episodes", type=int, default=400)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--ray",
        dest="cluster",
        metavar="ADDRESS",
        default=None,
        help="run the scenes as Ray tasks: 'local' (a cluster on this machine), 'auto' or an address",
    )
    parser.add_argument("--out", type=pathlib.Path, default=RESULTS / "soak.md", help="the report's path")
    parser.add_argument(
        "--rtol", type=float, default=None, help="the adaptive scenes under error control (Scene.rtol)"
    )
    args = parser.parse_args()
    start = time.perf_counter()
    tallies, lost, times = soak_scenes(args.scenes, args.seed, check_cluster(args.cluster), args.rtol)
    tally, rejected, ends, growth, removed, worst, crashes, stops, tunnelled = tallies
    scene_time = time.perf_counter() - start
    episodes = soak_episodes(args.episodes, args.seed + 1)
    wall = time.perf_counter() - start

    def q(values, p):
        return f"{np.quantile(values, p):.2g}" if values else "-"

    lines = [
        "# Soak run (`python benchmarks/soak.py`)",
        "",
        f"Seed {args.seed}; {args.scenes} random scenes and {args.episodes} env episodes; wall time "
        f"{wall:.0f} s ({scene_time:.0f} s scenes"
        + (f" as Ray tasks on {args.cluster}" if args.cluster else "")
        + "), numba warm from the on-disk cache."
        + (
            f" Adaptive scenes under error control, Scene.rtol = {args.rtol:g} (contact_error "
            '"impulse"), instead of impulse_tol = 5e-3 N s.'
            if args.rtol is not None
            else ""
        )
        + (f" Scenes lost with their Ray worker: {', '.join(str(t.index) for t in lost)}." if lost else ""),
        "",
        "## Random scenes",
        "",
        "| cases | BE / GA | accepted steps | rejected steps | non-finite | tunnelling "
        "| energy growth (BE / GA) | above start by collision push-out |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|",
        f"| {tally['cases']} | {tally['backward_euler']} / {tally['generalized_alpha']} "
        f"| {tally['steps']:,} | "
        f"{sum(rejected.values()):,} | {tally['non-finite']} | {tally['tunnelling']} | "
        f"{tally['energy growth backward_euler']} / {tally['energy growth generalized_alpha']} | "
        f"{tally['push-out above start']} |",
        "",
        "Energy growth: the total energy rose above its start value by more than 1e-9 of the start's "
        "sum of |energy parts| plus what the collision impulses' push-out created in the run "
        "(`SimulationStats.collision_gain`, the one source of energy without actuation); the last "
        "column counts runs that rose above the start by no more than that push-out. The energy "
        f"budget removed a step's excess in {tally['projected steps']:,} accepted steps of "
        f"{tally['projected runs']} runs.",
        "",
        "Rejected steps by reason: " + ", ".join(f"{k} {rejected[k]:,}" for k in REASONS) + ".",
        "",
        *times,
        f"Newton's rescue (`Scene.newton_rescue_max_iter`) took {tally['rescued steps']:,} steps in "
        f"{tally['rescued runs']} runs (each a run that stopped at `dt_min` without it).",
        "",
        f"Deepest node below a ground in any accepted state: {tally['deepest']:.2g} m (tolerance "
        f"{GROUND_TOLERANCE:g} m)."
        + "".join(
            f" Scene {i}: {depth:.2g} m below a ground, {inside:.2g} m inside another ring."
            for i, depth, inside in tunnelled
        ),
        "",
        "| how the run ended | runs |",
        "|---|---:|",
        *[f"| {k} | {v} |" for k, v in ends.most_common()],
        "",
        "Energy growth, relative to the start's sum of |energy parts| (max of E(t) - E(0)); "
        "quantiles over finite runs:",
        "",
        "| integrator | runs | median | 99 % | max | energy the budget removed: 99 % | max |",
        "|---|---:|---:|---:|---:|---:|---:|",
        *[
            f"| {k} | {len(v)} | {q(v, 0.5)} | {q(v, 0.99)} | {q(v, 1.0)} | {q(removed[k], 0.99)} "
            f"| {q(removed[k], 1.0)} |"
            for k, v in growth.items()
        ],
        "",
    ]
    if stops:
        lines += ["Stops (scene index: how, at t of t_end; ring N, h/R, friction):", ""]
        for index, how, t, t_end, scene in stops:
            r = scene.rings[0]
            lines.append(
                f"* {index}: {how}, at {t:.4g} of {t_end:.4g} s; {len(scene.rings)} ring(s) of N "
                f"{r.n_nodes}, h/R {r.thickness / r.radius:.3g}, friction {scene.grounds[0].friction:.2f}"
            )
        lines.append("")
    for index, scene, t_end, where in crashes:
        lines += [f"Crash in scene {index} (t_end {t_end:.4g} s): `{scene}`", "", "```", *where, "```", ""]
    if worst:
        lines += ["Largest rises above the start (growth / collision push-out; scene, t_end):", ""]
        for g, gain, scene, t_end in worst[:5]:
            r = scene.rings[0]
            lines.append(
                f"* {g:.2g} / {gain:.2g}: {scene.integrator}, rho_inf {scene.rho_infinity:.2f}, "
                f"dt {scene.dt:.2g} s "
                f"{'adaptive' if scene.adaptive else 'fixed'}, N {r.n_nodes}, E {r.youngs_modulus:.3g} Pa, "
                f"h/R {r.thickness / r.radius:.3g}, p {r.pressure}, spin {r.angular_velocity:.1f} rad/s, "
                f"v {tuple(round(c, 1) for c in r.velocity)} m/s, {len(scene.rings)} ring(s), "
                f"damping {scene.damping:g}, t_end {t_end:.3f} s"
            )
        lines.append("")
    lines += [
        "## Env episodes (InflatedBall-v3, fast preset)",
        "",
        "| episodes | env steps | non-finite | out of bounds | below ground | simulator failures |",
        "|---:|---:|---:|---:|---:|---:|",
        f"| {episodes['episodes']} | {episodes['env steps']:,} | {episodes['non-finite']} | "
        f"{episodes['out of bounds']} | {episodes['below ground']} | "
        f"{sum(v for k, v in episodes.items() if k.startswith('sim failure'))} |",
        "",
        "Episode ends: "
        + (
            ", ".join(f"{k[7:]} {v}" for k, v in sorted(episodes.items()) if k.startswith("ended: "))
            or "none"
        )
        + ".",
        "",
    ]
    text = "\n".join(lines)
    print(text)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    write_text(args.out, text)


if __name__ == "__main__":
    main()
