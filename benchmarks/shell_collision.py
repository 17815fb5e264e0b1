"""Two default balls (``Shell()``, 162 vertices) colliding head on without gravity, at 2, 5 and 20 m/s
closing speed (half each, along x, starting 1.4 cm apart), ``Scene`` defaults otherwise
(generalized-alpha, rho_inf = 0.9, rtol = 1e-4, dhat = 1 mm, frictionless contact); and what the
contact code costs a scene that does not use it.

    taskset -c 0 python benchmarks/shell_collision.py --baseline DIR  # writes results/shell_collision.md

Each collision runs until the balls are apart again (the gap's closing time plus 30 ms). Measured:
accepted steps, rejections, Newton and CG iterations, the stepping's wall time and ``simulate``'s
CPU time (numba warm, one core; the machine is shared, so CPU time is the steadier), the largest
total linear momentum over the run against one ball's ``m v / 2``, the smallest distance of a
contact pair (point-triangle or edge-edge) within ``dhat`` over the records, the energy left in the
balls (kinetic, skin, gas: ``E_end - U_0`` against the start's kinetic energy ``K_0``; ``U_0`` the
start's potential), the coefficient of restitution (the centres' separation speed over their
approach speed) and the contact time (from the first to the last record with a contact force between
the balls).

The cost of the contact code to a scene without contact: a single ball's drop from 0.5 m through its
first bounce (to 0.8 s, ground friction 0.5), run alternately by this code and by the code in
``--baseline DIR`` (a checkout without the contact code, e.g. ``git worktree add DIR main``), each
``REPEATS`` times in fresh processes (numba warm), the least CPU time kept; the final positions of
both must be the same bit for bit.
"""

import argparse
import json
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pathlib  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from ballenv.files import write_text  # noqa: E402
from ballenv.shell import Scene, Shell, simulate  # noqa: E402
from ballenv.shell.simulation import build  # noqa: E402
from ballenv.shell.step import implicit  # noqa: E402
from ballenv.shell.step.jointdata import make_joint  # noqa: E402
from ballenv.shell.touch import broadphase, contact  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
ROOT = pathlib.Path(__file__).resolve().parents[1]
SPEEDS = (2.0, 5.0, 20.0)  # m/s closing
START_GAP = 0.014  # m between the inflated balls (radius 0.1277 m)
CENTRE = 0.1277 + START_GAP / 2  # m: each centre's distance from the origin
AFTER = 0.03  # s simulated after the gap would have closed
REPEATS = 5
DROP_SCRIPT = """
import hashlib, json, os, sys, time
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
from ballenv.shell import Ground, Scene, Shell, simulate
scene = Scene(shells=[Shell(position=(0.0, 0.0, 0.5))], grounds=[Ground(friction=0.5)])
simulate(scene, t_end=0.01)  # warm
cpu = time.process_time()
traj = simulate(scene, t_end=0.8)
cpu = time.process_time() - cpu
digest = hashlib.sha256(traj.x[-1].tobytes()).hexdigest()[:16]
print(json.dumps({"wall": traj.stats.wall_time, "cpu": cpu, "steps": traj.stats.steps, "x": digest}))
"""


def head_on(speed: float) -> Scene:
    """The two balls closing at ``speed`` (m/s)."""
    half = speed / 2
    shells = [
        Shell(position=(-CENTRE, 0, 0), velocity=(half, 0, 0)),
        Shell(position=(CENTRE, 0, 0), velocity=(-half, 0, 0)),
    ]
    return Scene(shells=shells, gravity=0.0)


def closest_pair(scene: Scene, x: np.ndarray) -> float:
    """The smallest distance (m) of a pair within ``dhat`` at ``x`` (2, V, 3), inf if none."""
    _, steps = build(scene)
    model = steps[0].problem.model
    rest = np.array([st.problem.model.rest for st in steps])
    jt = make_joint((model.triangles, model.edges), rest, np.ones(2), scene.contact_distance, False, 4)
    lows = []
    for xt in x:
        flat = np.ascontiguousarray(xt.reshape(-1, 3))
        n = broadphase.find_pairs(jt.candidates, flat, np.zeros_like(flat), scene.contact_distance, jt.box)
        lows.append(float(contact.min_distance(jt.candidates.pairs, n, flat, jt.scratch)))
    return min(lows)


def collision(speed: float) -> dict:
    """The head-on collision at ``speed`` (m/s): the module doc's measurements."""
    scene = head_on(speed)
    cpu = time.process_time()
    traj = simulate(scene, t_end=START_GAP / speed + AFTER)
    cpu = time.process_time() - cpu
    _, steps = build(scene)
    mass = steps[0].problem.model.mass
    momentum = np.abs(np.einsum("i,tsik->tk", mass, traj.v)).max() / (mass.sum() * speed / 2)
    centre_v = np.einsum("i,tsik->tsk", mass, traj.v) / mass.sum()
    energy = [
        sum(implicit.total_energy(st, traj.x[t, k], traj.v[t, k]) for k, st in enumerate(steps))
        for t in (0, -1)
    ]
    kinetic0 = 0.5 * 2 * mass.sum() * (speed / 2) ** 2
    touching = np.nonzero(np.abs(traj.contact_force).max(axis=(1, 2, 3)) > 0.0)[0]
    s = traj.stats
    return {
        "speed": speed,
        "steps": s.steps,
        "rejections": s.rejections,
        "newton": s.newton_iterations,
        "cg": s.cg_iterations,
        "wall": s.wall_time,
        "cpu": cpu,
        "momentum": momentum,
        "closest": closest_pair(scene, traj.x),
        "energy": (energy[1] - (energy[0] - kinetic0)) / kinetic0,
        "restitution": (centre_v[-1, 1, 0] - centre_v[-1, 0, 0]) / speed,
        "contact_time": traj.t[touching[-1]] - traj.t[touching[0]] if len(touching) else 0.0,
    }


def drop(directory: str) -> dict:
    """The single ball's drop run by the code in ``directory`` in a new process."""
    env = {**os.environ, "PYTHONPATH": directory}
    out = subprocess.run(
        [sys.executable, "-c", DROP_SCRIPT],
        env=env,
        capture_output=True,
        text=True,
        check=True,
        cwd=directory,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def drops(baseline: str) -> dict:
    """The fastest of ``REPEATS`` alternate runs of this code and the baseline's."""
    runs: dict[str, list[dict]] = {"this": [], "baseline": []}
    for _ in range(REPEATS):
        runs["this"].append(drop(str(ROOT)))
        runs["baseline"].append(drop(baseline))
    best = {k: min(v, key=lambda r: r["cpu"]) for k, v in runs.items()}
    same = len({r["x"] for v in runs.values() for r in v}) == 1
    return {**best, "same": same, "cpus": {k: [r["cpu"] for r in v] for k, v in runs.items()}}


def table(rows: list[dict]) -> str:
    head = (
        "| closing speed (m/s) | steps | rejected | Newton iterations | CG iterations | wall (s) | CPU (s) "
        "| momentum error | closest pair (mm) | energy left | restitution | contact time (ms) |\n"
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n"
    )
    body = "".join(
        f"| {r['speed']:g} | {r['steps']} | {r['rejections']} | {r['newton']} | {r['cg']} "
        f"| {r['wall']:.2f} | {r['cpu']:.2f} "
        f"| {r['momentum']:.1e} | {1e3 * r['closest']:.4f} | {r['energy']:.4f} | {r['restitution']:.4f} "
        f"| {1e3 * r['contact_time']:.2f} |\n"
        for r in rows
    )
    return head + body


def drop_table(d: dict) -> str:
    def row(name: str, key: str) -> str:
        runs = ", ".join(f"{c:.3f}" for c in d["cpus"][key])
        return f"| {name} | {d[key]['steps']} | {d[key]['wall']:.3f} | {d[key]['cpu']:.3f} | {runs} |\n"

    head = "| code | steps | wall (s) | CPU (s), fastest | CPU (s), each run |\n|---|---:|---:|---:|---|\n"
    return head + row("this branch", "this") + row("without the contact code", "baseline")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--baseline", required=True, help="a checkout without the contact code (module doc)")
    args = parser.parse_args()
    simulate(head_on(2.0), t_end=0.004)  # warm: the shells' steps apart
    simulate(head_on(20.0), t_end=0.002)  # and the joint step
    rows = [collision(v) for v in SPEEDS]
    single = drops(args.baseline)
    page = (
        "# Two balls colliding head on\n\n"
        "`python benchmarks/shell_collision.py --baseline DIR` (see its docstring): two default balls "
        "(162 vertices each) closing at 2, 5 and 20 m/s without gravity, until they are apart again.\n\n"
        + table(rows)
        + "\nMomentum error: the largest total linear momentum over the run against one ball's `m v / 2`. "
        "Closest pair: the smallest distance of a point-triangle or edge-edge pair over the records. Energy "
        "left: the balls' energy at the end above their start's potential, against the start's kinetic "
        "energy (generalized-alpha with rho_inf = 0.9 dissipates the rest). Restitution: separation "
        "speed over approach speed of the centres. Contact time: first to last record with a force "
        "between the balls.\n\n"
        "A single ball's drop from 0.5 m to 0.8 s (through its first bounce), this code against a checkout "
        f"without the contact code, {REPEATS} runs each alternately in new processes; final positions "
        f"the same bit for bit: {'yes' if single['same'] else 'NO'}.\n\n" + drop_table(single)
    )
    write_text(RESULTS / "shell_collision.md", page)
    print(page)


if __name__ == "__main__":
    main()
