"""The 3-D shell's cost in simulated time: a drop from 0.5 m and three bounces of the default ball
(``Shell()``: R = 0.12 m, E = 5 MPa, nu = 0.45, h = 3 mm, rho = 1100 kg/m^3, p = 55 kPa, isothermal
gas) on a flat ground with friction 0.5, ``Scene`` defaults otherwise (generalized-alpha, rho_inf =
0.9, adaptive steps with rtol = 1e-4, no damping), on icospheres of 162 and 642 vertices; then the
same ball with the fidelity preset of its mesh (``ballenv.shell.presets``: "fast" on 162 vertices,
"balanced" on 642).

    taskset -c 0 python benchmarks/shell_drop.py                     # writes benchmarks/results/shell_drop.md
    taskset -c 0 python benchmarks/shell_drop.py --baseline DIR      # also runs the code checked out in DIR

The run starts with the centre at 0.5 m, at rest, and ends at the touchdown after the third apex
(the drop and three bounces; a contact may count more than one touchdown, where the lowest
vertices leave the barrier's reach for a moment). Wall time is ``simulate``'s stepping
(``Trajectory.stats.wall_time``, pro rata of the steps up to that touchdown), numba warm (a short
run touching the ground first), on one core (OPENBLAS_NUM_THREADS=1; the script pinned by
taskset), on a 2-core machine shared with other jobs (the same run varies by up to 2-3x from day
to day). Targets: 162 vertices at >= 10x real time, 642 at >= 1x.

First-apex error: the first apex's height against that of a converged run of the same mesh (rtol =
1e-6, to the first apex only), relative. With ``--baseline DIR``, each row's run is also made by
the code in DIR (a checkout of an earlier version, e.g. ``git archive <commit> | tar -x -C DIR``) in
a subprocess just before it, and the speed-up is its wall time over this code's. Also measured: the
per-step cost against the vertex count up to 2562 (the first 0.32 s: the fall, the first impact and
the start of the rebound), and the first ``simulate`` with an empty numba cache in a new process
(the shell's compile time).
"""

import argparse
import json
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pathlib  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402

from ballenv.files import write_text  # noqa: E402
from ballenv.shell import Ground, Scene, Shell, simulate  # noqa: E402
from ballenv.shell.presets import with_fidelity  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
ROOT = pathlib.Path(__file__).resolve().parents[1]
DROP = 0.5  # m: the centre's start height
BOUNCES = 3
TARGETS = {2: 10.0, 3: 1.0}  # subdivisions -> the real-time factor asked for
DEFAULT_RTOL = 1e-4  # the Scene default
PRESETS = {2: "fast", 3: "balanced"}  # the preset of each mesh
REFERENCE_RTOL = 1e-6
FIRST_APEX_END = 0.65  # s: after the first apex (at about 0.56 s)
SCALING_END = 0.32  # s
BASELINE_SCRIPT = """
import json, os, sys
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
from ballenv.shell import Ground, Scene, Shell, simulate
from ballenv.shell.presets import with_fidelity
k, rtol, t_end, preset = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
low = Shell(subdivisions=k, position=(0.0, 0.0, 0.128), velocity=(0.0, 0.0, -1.0))
simulate(Scene(shells=[low], grounds=[Ground(friction=0.5)], rtol=rtol), t_end=0.005)  # compile
ball = Shell(subdivisions=k, position=(0.0, 0.0, 0.5))
scene = Scene(shells=[ball], grounds=[Ground(friction=0.5)], rtol=rtol)
traj = simulate(with_fidelity(scene, preset) if preset != "-" else scene, t_end=t_end)
print(json.dumps({"wall": traj.stats.wall_time, "steps": traj.stats.steps, "apex": traj.apexes()[0, 1]}))
"""
COLD_SCRIPT = """
import time
t0 = time.perf_counter()
from ballenv.shell import Ground, Scene, Shell, simulate
ball = Shell(position=(0.0, 0.0, 0.128), velocity=(0.0, 0.0, -1.0))
simulate(Scene(shells=[ball], grounds=[Ground(friction=0.5)]), t_end=0.005)
print(time.perf_counter() - t0)
"""


def scene_of(
    subdivisions: int, rtol: float, height: float = DROP, speed: float = 0.0, preset: str | None = None
) -> Scene:
    """The benchmark's drop on the ``subdivisions`` icosphere at ``rtol`` from ``height`` (m) at
    ``speed`` (m/s) downwards, or with the fidelity ``preset`` (its mesh and step control)."""
    ball = Shell(subdivisions=subdivisions, position=(0.0, 0.0, height), velocity=(0.0, 0.0, -speed))
    scene = Scene(shells=[ball], grounds=[Ground(friction=0.5)], rtol=rtol)
    return with_fidelity(scene, preset) if preset else scene


def warm(subdivisions: int, rtol: float) -> None:
    """Compiles what a drop runs, contact included (a short run touching the ground)."""
    simulate(scene_of(subdivisions, rtol, height=0.135, speed=1.0), t_end=0.005)


def baseline(directory: str, subdivisions: int, rtol: float, t_end: float, preset: str | None) -> dict:
    """The same run by the code in ``directory`` (its own ``preset``, if given): its wall time (s),
    steps, first apex (m)."""
    env = {**os.environ, "PYTHONPATH": directory}
    args = [str(subdivisions), str(rtol), str(t_end), preset or "-"]
    out = subprocess.run(
        [sys.executable, "-c", BASELINE_SCRIPT, *args],
        env=env, capture_output=True, text=True, check=True, cwd=directory,
    )  # fmt: skip
    return json.loads(out.stdout.strip().splitlines()[-1])


def reference_apex(subdivisions: int) -> float:
    """The first apex's height (m) of a converged run (module doc)."""
    return float(simulate(scene_of(subdivisions, REFERENCE_RTOL), t_end=FIRST_APEX_END).apexes()[0, 1])


def run(subdivisions: int, preset: str | None, reference: float, old: str | None) -> dict:
    """The drop of the ``subdivisions`` ball (``Scene`` defaults, or the fidelity ``preset``) up to
    the touchdown after its third apex."""
    rtol = DEFAULT_RTOL
    scene = scene_of(subdivisions, rtol, preset=preset)
    warm(subdivisions, rtol)
    t_end = 2.4
    before = baseline(old, subdivisions, rtol, t_end, preset) if old else None
    traj = simulate(scene, t_end=t_end)
    apexes = traj.apexes()
    last_apex = apexes[BOUNCES - 1, 0] if len(apexes) >= BOUNCES else t_end
    after = [t for t, _, kind, _ in traj.events if kind == "touchdown" and t > last_apex]
    simulated = after[0] if after else t_end
    share = sum(1 for t in traj.t[1:] if t <= simulated) / max(len(traj.t) - 1, 1)
    s = traj.stats
    wall = s.wall_time * share  # the stepping's time up to the last touchdown (steps pro rata)
    return {
        "vertices": scene.shells[0].n_vertices,
        "settings": f"preset {preset}" if preset else f"defaults (rtol {rtol:g})",
        "simulated": simulated,
        "wall": wall,
        "real_time": simulated / wall,
        "target": TARGETS[subdivisions],
        "apex": apexes[0, 1] if len(apexes) else float("nan"),
        "apex_error": (apexes[0, 1] - reference) / reference if len(apexes) else float("nan"),
        "apexes": ", ".join(f"{z:.4f}" for z in apexes[:BOUNCES, 1]),
        "touchdowns": sum(1 for t, _, kind, _ in traj.events if kind == "touchdown" and t <= simulated),
        "steps": round(s.steps * share),
        "rejections": s.rejections,
        "newton": round(s.newton_iterations * share),
        "cg": round(s.cg_iterations * share),
        "envelope": s.envelope_solves,
        "speedup": before["wall"] / s.wall_time if before else float("nan"),
        "old_wall_per_step": before["wall"] / before["steps"] if before else float("nan"),
    }


def scaling(subdivisions: int) -> dict:
    """Cost per step and per Newton iteration (ms) of the first ``SCALING_END`` s at rtol 1e-4."""
    scene = scene_of(subdivisions, DEFAULT_RTOL)
    warm(subdivisions, DEFAULT_RTOL)
    s = simulate(scene, t_end=SCALING_END).stats
    return {
        "vertices": scene.shells[0].n_vertices,
        "steps": s.steps,
        "per_step": 1e3 * s.wall_time / s.steps,
        "per_newton": 1e3 * s.wall_time / s.newton_iterations,
        "cg_per_newton": s.cg_iterations / s.newton_iterations,
    }


def cold_compile_seconds() -> float:
    """Wall time (s) of a new process's first short drop with an empty numba cache."""
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PYTHONPATH": str(ROOT)}
        out = subprocess.run(
            [sys.executable, "-c", COLD_SCRIPT], env=env, capture_output=True, text=True, check=True
        )
        return float(out.stdout.strip().splitlines()[-1])


def table(rows: list[dict]) -> str:
    head = (
        "| vertices | settings | simulated (s) | wall (s) | wall per simulated s | x real time | target "
        "| ratio to target | first apex (m) | first-apex error | apexes (m) | touchdowns | steps "
        "| rejected | Newton iterations | per step | CG iterations | envelope solves "
        "| wall per step (ms) | old wall per step (ms) | speed-up |\n"
        "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:"
        "|---:|---:|---:|\n"
    )
    body = "".join(
        f"| {r['vertices']} | {r['settings']} | {r['simulated']:.3f} | {r['wall']:.1f} "
        f"| {r['wall'] / r['simulated']:.1f} "
        f"| {r['real_time']:.3f} | {r['target']:g} | {r['real_time'] / r['target']:.4f} | {r['apex']:.4f} "
        f"| {100 * r['apex_error']:+.2f} % | {r['apexes']} | {r['touchdowns']} | {r['steps']} "
        f"| {r['rejections']} | {r['newton']} | {r['newton'] / r['steps']:.2f} "
        f"| {r['cg']} | {r['envelope']} | {1e3 * r['wall'] / r['steps']:.2f} "
        f"| {r['old_wall_per_step'] * 1e3:.2f} | {r['speedup']:.2f} |\n".replace(" nan ", " - ")
        for r in rows
    )
    return head + body


def scaling_table(rows: list[dict]) -> str:
    head = (
        "| vertices | steps | wall per step (ms) | per vertex (us) | wall per Newton iteration (ms) "
        "| CG iterations per Newton |\n|---:|---:|---:|---:|---:|---:|\n"
    )
    body = "".join(
        f"| {r['vertices']} | {r['steps']} | {r['per_step']:.2f} | {1e3 * r['per_step'] / r['vertices']:.2f} "
        f"| {r['per_newton']:.2f} | {r['cg_per_newton']:.1f} |\n"
        for r in rows
    )
    return head + body


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--baseline", help="a checkout of the code to compare with (module doc)")
    args = parser.parse_args()
    compile_s = cold_compile_seconds()
    rows = []
    for k in (2, 3):
        reference = reference_apex(k)
        rows += [run(k, None, reference, args.baseline), run(k, PRESETS[k], reference, args.baseline)]
    scale = [scaling(k) for k in (2, 3, 4)]
    name = pathlib.Path(__file__).relative_to(pathlib.Path(__file__).parents[1])
    text = (
        "# The 3-D shell: a drop and three bounces\n\n"
        f"`python {name}` (see its docstring): the default ball dropped from a centre height of 0.5 m, "
        "simulated to the touchdown after its third apex.\n\n" + table(rows) + "\n"
        "Real time is simulated seconds per wall-clock second; the ratio to target is that over the "
        "target (>= 1 meets it). The apexes are the centre of mass's heights, located inside the steps. "
        f"First-apex error: against a run at rtol = {REFERENCE_RTOL:g} of the same mesh. "
        "Old wall per step and speed-up: the code given by `--baseline` (with its own preset's "
        "settings on the preset rows), run just before in the same minutes, over the whole run to "
        "2.4 s (- where not run).\n\n"
        f"Cost against the vertex count (the first {SCALING_END:g} s, rtol = {DEFAULT_RTOL:g}):\n\n"
        + scaling_table(scale)
        + "\nThe first drop in a new process with an empty numba cache (compiling the shell): "
        f"{compile_s:.0f} s.\n"
    )
    write_text(RESULTS / "shell_drop.md", text)
    sys.stdout.write(text)


if __name__ == "__main__":
    main()
