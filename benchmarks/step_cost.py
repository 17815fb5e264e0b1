"""Cost of the implicit step: microseconds per step and per Newton iteration vs node count, for each
integrator; numba compile time (cold and from cache) and import time.

    python benchmarks/step_cost.py            # writes benchmarks/results/step_cost.md and .png

Scene: one inflated ring (R = 0.1 m, E = 10 MPa, h = 2 mm, 30 kPa) in free flight under gravity,
released from a slightly squashed shape so Newton has real work, fixed dt = 1e-4 s, 0.1 s simulated.
Median of 5 repeats with numba warm. OPENBLAS_NUM_THREADS=1.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pathlib  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402

import numpy as np  # noqa: E402

from ballenv.files import write_text  # noqa: E402
from ballenv.physics import Ring, Scene, simulate  # noqa: E402
from ballenv.physics.base.ring import inflated_radius  # noqa: E402

NODE_COUNTS = (16, 32, 64, 128, 256, 512)
INTEGRATORS = ("backward_euler", "generalized_alpha")
RESULTS = pathlib.Path(__file__).parent / "results"


def _squashed(n_nodes):
    """The inflated circle squashed by 1 % into an ellipse, centred at (0, 1) m."""
    r = inflated_radius(Ring(n_nodes=n_nodes))
    theta = 2 * np.pi * np.arange(n_nodes) / n_nodes
    return np.stack([1.01 * r * np.cos(theta), 1.0 + 0.99 * r * np.sin(theta)], axis=1)


def step_cost(n_nodes, integrator, damping, repeats=5, t_end=0.1):
    """(us per step, us per Newton iteration, Newton iterations per step), median of repeats."""
    scene = Scene(rings=[Ring(n_nodes=n_nodes)], integrator=integrator, dt=1e-4, damping=damping)
    x0 = _squashed(n_nodes)
    simulate(scene, 1e-3, x0=x0)
    per_step, per_newton, iters = [], [], []
    for _ in range(repeats):
        traj = simulate(scene, t_end, x0=x0, output_dt=t_end)
        s = traj.stats
        per_step.append(s.wall_time / s.steps * 1e6)
        per_newton.append(s.wall_time / max(s.newton_iterations, 1) * 1e6)
        iters.append(s.newton_iterations / s.steps)
    return float(np.median(per_step)), float(np.median(per_newton)), float(np.median(iters))


_COMPILE_SNIPPET = """
import time
t0 = time.perf_counter()
from ballenv.physics import Ring, Scene, simulate
t1 = time.perf_counter()
for integrator in ("backward_euler", "generalized_alpha"):
    simulate(Scene(rings=[Ring(n_nodes=16)], integrator=integrator, damping=1.0), 1e-3)
t2 = time.perf_counter()
print(t1 - t0, t2 - t1)
"""


def compile_times(snippet=_COMPILE_SNIPPET):
    """(import s, cold compile s, cached start s): ``snippet`` (which prints the seconds of its import
    and of its first compiled call) run twice in fresh interpreters sharing an empty numba cache."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        runs = []
        for _ in range(2):
            out = subprocess.run(
                [sys.executable, "-c", snippet], env=env, capture_output=True, text=True, check=True
            )
            runs.append([float(v) for v in out.stdout.split()])
    return runs[0][0], runs[0][1], runs[1][1]


def main():
    RESULTS.mkdir(exist_ok=True)
    rows = []
    from tqdm import tqdm

    cases = [(n, i, d) for d in (0.0, 5.0) for i in INTEGRATORS for n in NODE_COUNTS]
    for n, integrator, damping in tqdm(cases, desc="step cost"):
        rows.append((n, integrator, damping, *step_cost(n, integrator, damping)))
    imp, cold, cached = compile_times()
    lines = [
        "| N | integrator | damping (1/s) | us / step | us / Newton iteration | Newton iterations / step |",
        "|---:|---|---:|---:|---:|---:|",
    ]
    lines += [f"| {n} | {i} | {d:g} | {s:.1f} | {it:.1f} | {k:.2f} |" for n, i, d, s, it, k in rows]
    growth = {}
    for i in INTEGRATORS:
        for d in (0.0, 5.0):
            cost = {n: s for n, ii, dd, s, _, _ in rows if ii == i and dd == d}
            growth[(i, d)] = cost[512] / cost[64]
    lines += ["", "| integrator | damping | cost(N=512) / cost(N=64) |", "|---|---:|---:|"]
    lines += [f"| {i} | {d:g} | {g:.1f}x |" for (i, d), g in growth.items()]
    lines += [
        "",
        f"import ballenv.physics: {imp:.2f} s; numba compile, cold: {cold:.1f} s; "
        f"start from cache: {cached:.2f} s",
    ]
    table = "\n".join(lines)
    write_text(RESULTS / "step_cost.md", table + "\n")
    print(table)
    _plot(rows)


def _plot(rows):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for i in INTEGRATORS:
        for d in (0.0, 5.0):
            pts = [(n, s) for n, ii, dd, s, _, _ in rows if ii == i and dd == d]
            ax.loglog(*zip(*pts, strict=True), "o-", label=f"{i}, damping {d:g}/s")
    ns = np.array(NODE_COUNTS, dtype=float)
    ax.loglog(ns, ns * pts[2][1] / 64, "k:", label="O(N)")
    ax.set_xlabel("nodes N")
    ax.set_ylabel("wall time per step (us)")
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(RESULTS / "step_cost.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
