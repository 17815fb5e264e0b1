"""Throughput of the 3-D ball's envs (InflatedBall3D-v0, InflatedBall3DPaddle-v0): env steps per
second on one core with random actions at the "fast" preset (162 vertices), against InflatedBall-v3
(the ring) measured in the same minute, with where the time goes; and the native vector env's
scaling from one thread to two, what looser step control would buy and what each part of the
implicit step costs.

    python benchmarks/env3d_throughput.py [--steps N]   # writes benchmarks/results/env3d_throughput.md

Single process, numba warm (a warm-up of 50 steps), OPENBLAS_NUM_THREADS=1. Steps/s counts env steps
including resets, best of 3 repeats of ``--steps`` steps (seeded actions). "Simulator steps" are the
accepted implicit steps per env step, "kernel share" the fraction of the time spent in the compiled
implicit step. The machine's speed varies from day to day: the ratio to the ring's env, measured
alternately with it, is the figure to compare across runs. The sweep's work per env step (steps
tried, Newton and CG iterations) does not depend on the machine; the parts' prices are best of 5
repeats of 300 calls in one compiled loop, on the paddle env's state after 60 steps.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import pathlib  # noqa: E402
import time  # noqa: E402
from typing import NamedTuple  # noqa: E402

import gymnasium as gym  # noqa: E402

import ballenv  # noqa: E402, F401
from ballenv.files import write_text  # noqa: E402
from ballenv.physics.base.jit import kernel  # noqa: E402
from ballenv.shell import simulate  # noqa: E402
from ballenv.shell.solve.stepsolve import CG_MAX_ITER  # noqa: E402
from ballenv.shell.step import implicit, increment  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
CASES = (("InflatedBall3D-v0", "pressure"), ("InflatedBall3DPaddle-v0", "paddle"))
RING = {"pressure": "InflatedBall-v3", "paddle": "InflatedBallPaddle-v3"}
TARGET = 1000.0  # env steps/s at 162 vertices, fast preset
VECTOR_ENVS = 8
SWEEP_RTOLS = (1e-3, 3e-3, 1e-2, 3e-2)  # the fast preset's, and looser
SWEEP_STEPS = 300


def run(env, steps: int, seed: int) -> tuple[float, int, int]:
    """(steps/s, accepted simulator steps, Newton iterations) of ``steps`` random-action env steps."""
    env.action_space.seed(seed)
    env.reset(seed=seed)
    sim_steps, newton, start = 0, 0, time.perf_counter()
    for _ in range(steps):
        _, _, term, trunc, _ = env.step(env.action_space.sample())
        if term or trunc:
            sim_steps, newton = sim_steps + _stats(env)[0], newton + _stats(env)[1]
            env.reset()
    sim_steps, newton = sim_steps + _stats(env)[0], newton + _stats(env)[1]
    return steps / (time.perf_counter() - start), sim_steps, newton


def _stats(env) -> tuple[int, int]:
    """(accepted simulator steps, Newton iterations) of the episode so far (0, 0 for the ring)."""
    ball = getattr(env.unwrapped, "ball", None)
    if ball is None:
        return 0, 0
    stats = ball.sim.run.stats
    return stats.steps, stats.newton_iterations


def kernel_share(env, steps: int) -> float:
    """Fraction of the time of ``steps`` env steps spent in the compiled implicit step."""
    spent = [0.0]
    kernel = implicit.step_kernel

    def timed(*args):
        t = time.perf_counter()
        try:
            return kernel(*args)
        finally:
            spent[0] += time.perf_counter() - t

    implicit.step_kernel = timed
    try:
        rate = run(env, steps, 99)[0]
    finally:
        implicit.step_kernel = kernel
    return spent[0] * rate / steps


def measure(env_id: str, mode: str, steps: int) -> dict[str, float]:
    env, ring = gym.make(env_id), gym.make(RING[mode])
    run(env, 50, 0)
    run(ring, 50, 0)
    best, ring_best, sim_steps, newton = 0.0, 0.0, 0, 0
    for repeat in range(3):
        rate, sim_steps, newton = run(env, steps, repeat)
        best = max(best, rate)
        ring_best = max(ring_best, run(ring, 2000, repeat)[0])
    return {
        "rate": best,
        "ring": ring_best,
        "sim_steps": sim_steps / steps,
        "newton": newton / max(sim_steps, 1),
        "kernel": kernel_share(env, steps),
    }


def vector_rate(threads: int, steps: int, seed: int) -> float:
    """Env steps/s of the paddle mode's native vector env of ``VECTOR_ENVS`` envs on ``threads``."""
    vec = gym.make_vec(CASES[1][0], num_envs=VECTOR_ENVS, num_threads=threads)
    vec.action_space.seed(seed)
    vec.reset(seed=seed)
    start = time.perf_counter()
    for _ in range(steps):
        vec.step(vec.action_space.sample())
    rate = steps * VECTOR_ENVS / (time.perf_counter() - start)
    vec.close()
    return rate


def vector_scaling(steps: int) -> tuple[float, float]:
    """(1 thread, 2 threads) env steps/s, best of 3 alternating repeats."""
    vector_rate(1, 10, 0)
    one, two = 0.0, 0.0
    for repeat in range(3):
        one = max(one, vector_rate(1, steps, repeat))
        two = max(two, vector_rate(2, steps, repeat))
    return one, two


def first_apex(scene, rtol: float, **numerics: float) -> float:
    """First apex (m) of the env's ball dropped from 1 m under ``scene`` with ``rtol`` (and any
    further numerical settings)."""
    ball = dataclasses.replace(scene.shells[0], position=(0.0, 0.0, 1.0))
    run = dataclasses.replace(scene, shells=(ball,), rtol=rtol, **numerics)
    return float(simulate(run, 1.2).apexes()[0, 1])


class Work(NamedTuple):
    """What the env steps of one run cost: steps/s, and per env step the implicit steps tried (the
    rejected ones included) and accepted, their Newton and CG iterations and the compiled step's
    time (ms)."""

    rate: float
    tried: float
    accepted: float
    newton: float
    cg: float
    kernel_ms: float


def work(env, steps: int, seed: int) -> Work:
    """The :class:`Work` of ``steps`` random-action env steps of ``env``."""
    tally = [0, 0, 0, 0.0]  # tries, Newton iterations, CG iterations, seconds
    kernel = implicit.step_kernel

    def counted(*args):
        t = time.perf_counter()
        try:
            result = kernel(*args)
        finally:
            tally[3] += time.perf_counter() - t
        tally[0] += 1
        tally[1] += result[1]
        tally[2] += result[2]
        return result

    implicit.step_kernel = counted
    try:
        rate, accepted, _ = run(env, steps, seed)
    finally:
        implicit.step_kernel = kernel
    tried, newton, cg, seconds = tally
    return Work(rate, tried / steps, accepted / steps, newton / steps, cg / steps, 1e3 * seconds / steps)


def rtol_sweep() -> list[tuple[float, Work, Work, float]]:
    """(rtol, the pressure env's Work, the paddle env's Work, first-apex error) per ``SWEEP_RTOLS``:
    the env's step control loosened, against a converged drop (rtol 1e-5, dt 1e-3 s, newton_tol 1e-9)."""
    scene = gym.make(CASES[0][0]).unwrapped.ball.scene
    reference = first_apex(scene, 1e-5, dt=1e-3, newton_tol=1e-9)
    rows = []
    for rtol in SWEEP_RTOLS:
        costs = []
        for env_id, _ in CASES:
            env = gym.make(env_id)
            env.unwrapped.ball.scene = dataclasses.replace(env.unwrapped.ball.scene, rtol=rtol)
            costs.append(work(env, SWEEP_STEPS, 0))
        rows.append((rtol, costs[0], costs[1], first_apex(scene, rtol) / reference - 1.0))
    return rows


@kernel
def _gradients(method, st, n):
    sp, wk = st.start, st.work
    for _ in range(n):
        increment.incremental_gradient(method, st, sp, wk.x, wk, wk.grad, wk.blocks)
    return 0


@kernel
def _potentials(method, st, n):
    sp, wk = st.start, st.work
    total = 0.0
    for _ in range(n):
        total += increment.incremental(method, st, sp, wk.x, wk)
    return total


@kernel
def _matrices(st, hinges, n):
    sp, wk = st.start, st.work
    for _ in range(n):
        if hinges:
            wk.bending_age[0] = -1  # the hinges' matrices are evaluated again, not kept
        increment.newton_matrix(st, sp, wk.x, wk, True)
    return 0


@kernel
def _solves(method, st, rtol, n):
    """``n`` Newton directions at ``wk.x`` on the element matrices already there; their CG
    iterations."""
    sp, wk = st.start, st.work
    iterations = 0
    for _ in range(n):
        iterations += increment.direction(st, sp, wk.x, wk.grad, wk.blocks, wk, wk.dx, False, rtol)
    return iterations


def _price(call, *args) -> tuple[float, int]:
    """(us per call, its result per call) of ``call(*args, n)`` (``n`` calls in one compiled loop),
    best of 5 repeats of n = 300."""
    n, best, result = 300, float("inf"), 0
    call(*args, 1)
    for _ in range(5):
        start = time.perf_counter()
        result = call(*args, n)
        best = min(best, (time.perf_counter() - start) / n)
    return 1e6 * best, result / n


def part_prices() -> list[tuple[str, float]]:
    """(part, us) of a Newton iteration of the paddle env's implicit step at 162 vertices."""
    env = gym.make(CASES[1][0])
    run(env, 60, 0)
    sim = env.unwrapped.ball.sim.run
    method, ref = sim.method, sim.refs[0]
    implicit.step_kernel(method, ref, sim.x[0], sim.v[0], sim.a[0], 1e-3)  # fills the step's records
    wk = ref.record.work
    wk.x[:] = sim.x[0] + 1e-3 * sim.v[0]  # a Newton iterate away from the solution
    gradient = _price(_gradients, method, ref)[0]
    phi = _price(_potentials, method, ref)[0]
    triangles = _price(_matrices, ref, False)[0]
    with_hinges = _price(_matrices, ref, True)[0]
    _gradients(method, ref, 1)
    loose, loose_its = _price(_solves, method, ref, 1e-2)
    tight, tight_its = _price(_solves, method, ref, 1e-8)
    per_iteration = (tight - loose) / max(tight_its - loose_its, 1e-9)
    return [
        ("the gradient of Phi (with the contact's blocks)", gradient),
        ("Phi, once per line-search trial", phi),
        ("the element matrices: the triangles' (the hinges' kept)", triangles),
        ("the element matrices with the hinges' evaluated again (every 8th fresh assembly)", with_hinges),
        ("a CG iteration", per_iteration),
        (f"a solve's set-up (the operator, the preconditioner; {loose_its:.0f} to {tight_its:.0f} "
         f"of at most {CG_MAX_ITER} iterations measured)", loose - loose_its * per_iteration),
    ]  # fmt: skip


def page(rows: dict[str, dict[str, float]], steps: int, scaling: tuple[float, float], sweep, prices) -> str:
    lines = [
        "# The 3-D ball's envs: throughput",
        "",
        "`python benchmarks/env3d_throughput.py` (one core, random actions, fast preset: 162 vertices,",
        f"best of 3 repeats of {steps} env steps; the ring's env measured alternately in the same minutes).",
        "",
        "| env | env steps/s | target | ring's env steps/s | 3-D / ring | simulator steps per env step "
        "| Newton iterations per simulator step | time in the implicit step |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for env_id, r in rows.items():
        lines.append(
            f"| {env_id} | {r['rate']:.0f} | {TARGET:.0f} | {r['ring']:.0f} | {r['rate'] / r['ring']:.4f} "
            f"| {r['sim_steps']:.2f} | {r['newton']:.2f} | {100 * r['kernel']:.0f} % |"
        )
    one, two = scaling
    lines += [
        "",
        f"The native vector env (`gym.make_vec`, {VECTOR_ENVS} paddle-mode envs, random actions, best of",
        f"3 alternating repeats of {steps // VECTOR_ENVS} vector steps): {one:.0f} env steps/s on one",
        f"thread, {two:.0f} on two ({two / one:.2f}x). The implicit step releases Python's lock; the env's",
        "own Python runs one thread at a time.",
        "",
        f"Looser step control ({SWEEP_STEPS} env steps each, random actions; first apex of the env's ball",
        "dropped from 1 m against a converged drop) buys little speed for much error, so the env keeps",
        "the fast preset's rtol = 1e-3. Per env step, for each mode: the implicit steps tried (the",
        "rejected ones included) and accepted, their Newton and CG iterations, the compiled step's time:",
        "",
        "| rtol | mode | env steps/s | steps tried | accepted | Newton iterations | CG iterations "
        "| implicit step (ms) | first-apex error |",
        "|---:|---|---:|---:|---:|---:|---:|---:|---:|",
        *(
            f"| {r:g} | {mode} | {w.rate:.0f} | {w.tried:.2f} | {w.accepted:.2f} | {w.newton:.2f} "
            f"| {w.cg:.1f} | {w.kernel_ms:.2f} | {100 * e:+.2f} % |"
            for r, p, q, e in sweep
            for mode, w in (("pressure", p), ("paddle", q))
        ),
        "",
        "Longer steps are fewer but each costs more: the mass term `M / h^2` that holds Newton's",
        "matrix to the last step's motion weakens as `1 / h^2`, so each step takes more Newton",
        "iterations and each of those more CG iterations. The work per env step changes less than",
        "the step count.",
        "",
        "What the parts of one Newton iteration cost (us, the paddle env's ball in its state after 60",
        "steps, at 162 vertices, one core):",
        "",
        "| part | us |",
        "|---|---:|",
        *(f"| {name} | {us:.1f} |" for name, us in prices),
        "",
        "The rest of the time is Python: the step control, events and records between steps, each",
        "compiled call's unpacking of the step's records, and the env's actions, observation and",
        "reward. With random actions the pressure mode's pumping rings the ball's breathing mode, which",
        "the error control follows with steps of about a millisecond, most of them in flight; the",
        "paddle mode's strikes ring it less. A step in contact with friction took 22 Newton iterations",
        "before the contact vertices' own descent (`ballenv/shell/step/relax.py`), about 5 with it.",
        "",
    ]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=1000, help="env steps per repeat (default 1000)")
    args = parser.parse_args()
    rows = {}
    for env_id, mode in CASES:
        rows[env_id] = measure(env_id, mode, args.steps)
        print(env_id, {k: round(v, 3) for k, v in rows[env_id].items()}, flush=True)
    scaling = vector_scaling(args.steps // VECTOR_ENVS)
    print("vector, 1 and 2 threads", scaling, flush=True)
    sweep = rtol_sweep()
    print("rtol sweep", sweep, flush=True)
    prices = part_prices()
    print("parts", prices, flush=True)
    write_text(RESULTS / "env3d_throughput.md", page(rows, args.steps, scaling, sweep, prices))


if __name__ == "__main__":
    main()
