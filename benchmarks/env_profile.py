"""Where an env step's time goes: a per-phase profile of InflatedBall-v3 with random actions.

    python benchmarks/env_profile.py    # writes benchmarks/results/env_profile.md

For each fidelity preset and action mode, one env (single process, numba warm) takes random actions;
the stepper's counters give, per control step, the simulator steps, the rejected ones by reason and
the Newton iterations. The time of a control step is then split into phases, each timed on its own
(best of repeats, microseconds):

* Python: the Gymnasium wrappers, action parsing and the info dict (``env.step`` less the batch call);
* dispatch: calling the compiled step with no env active (unboxing its arrays);
* Newton iterations, by kernel, at the state the episode reached: residual (the effects' forces),
  Jacobian assembly (band + low-rank columns), factorisation and solve (band LU, Woodbury), times
  the iterations per control step;
* the rest of the physics: predictor, contact bookkeeping, energy guard, events, observation and
  reward (the batch call less dispatch less Newton).

Then the cold start: ``gym.make`` + ``reset`` and the first ``step`` in a fresh interpreter with an
empty numba cache (everything compiles), and again from the cache that run left.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pathlib  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import gymnasium as gym  # noqa: E402
import numpy as np  # noqa: E402
from numba import njit  # noqa: E402
from step_cost import compile_times  # noqa: E402

import ballenv  # noqa: E402, F401
from ballenv.envs import ENV_ID  # noqa: E402
from ballenv.envs.numerics import ENV_FIDELITIES  # noqa: E402
from ballenv.files import write_text  # noqa: E402
from ballenv.physics.base.layout import (
    COUNT_BY_REASON,
    COUNT_IMPULSE_REJECTED,
    COUNT_NEWTON,
    COUNT_REJECTED,
    COUNT_STEPS,
    COUNTERS,
    REJECTIONS,
)
from ballenv.physics.base.linalg import solve_band_low_rank  # noqa: E402
from ballenv.physics.build import build_workspace  # noqa: E402
from ballenv.physics.effects.assembly import ring_force, ring_jacobian  # noqa: E402
from ballenv.physics.step.integrator import coefficients  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
_COLD_START_SNIPPET = f"""
import time
t0 = time.perf_counter()
import gymnasium as gym
import ballenv
env = gym.make({ENV_ID!r})
env.reset(seed=0)
t1 = time.perf_counter()
env.step(env.action_space.sample())
t2 = time.perf_counter()
print(t1 - t0, t2 - t1)
"""
MODES = ("pressure", "paddle")
CONTROL_STEPS = 2000
REPEATS = 3


@njit(cache=True)
def _force_loop(model, x, v, force, count):
    for _ in range(count):
        ring_force(model, 0, x, v, force)


@njit(cache=True)
def _jacobian_loop(model, x, v, c_mass, c_x, c_v, ws, count):
    rank = 0
    for _ in range(count):
        rank = ring_jacobian(model, 0, x, v, c_mass, c_x, c_v, ws)
    return rank


@njit(cache=True)
def _solve_loop(band, ws, rank, count):
    for _ in range(count):
        ws.band[:] = band
        ws.res[:] = 1.0
        solve_band_low_rank(ws.band, ws.pos, ws.u, ws.w, rank, ws.res, ws.work, ws.cap, ws.coef)


def best_time(call, count, repeats=5):
    """Microseconds per unit of ``call(count)`` (best of ``repeats``)."""
    call(10)
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        call(count)
        best = min(best, (time.perf_counter() - start) / count * 1e6)
    return best


def kernel_costs(batch, h):
    """us per residual force, Jacobian assembly and factorisation + solve at env 0's state."""
    model = batch.model
    x = batch.state.x[0].copy()
    v = batch.state.v[0].copy()
    ws = build_workspace(x.shape[0])
    force = np.zeros_like(x)
    c_mass, c_x, c_v, _ = coefficients(batch.solver, h)
    count = 5000
    residual = best_time(lambda n: _force_loop(model, x, v, force, n), count)
    jacobian = best_time(lambda n: _jacobian_loop(model, x, v, c_mass, c_x, c_v, ws, n), count)
    rank = _jacobian_loop(model, x, v, c_mass, c_x, c_v, ws, 1)
    band = ws.band.copy()
    solve = best_time(lambda n: _solve_loop(band, ws, rank, n), count)
    return residual, jacobian, solve


def profile(preset, mode):
    """One row: per-control-step counts and the phase split (us per control step)."""
    env = gym.make(ENV_ID, action_mode=mode, fidelity=preset)
    env.reset(seed=0)
    env.action_space.seed(0)
    for _ in range(50):  # warm-up (compiles on the first run)
        env.step(env.action_space.sample())
    batch = env.unwrapped._batch
    best = np.inf
    for rep in range(REPEATS):
        actions = np.random.default_rng(rep).uniform(-1.0, 1.0, (CONTROL_STEPS, 1)).astype(np.float32)
        totals = np.zeros(COUNTERS.size, dtype=np.int64)
        env.reset(seed=rep)
        wall = 0.0
        for k in range(CONTROL_STEPS):
            before = batch.counters[0].copy()
            start = time.perf_counter()
            _, _, terminated, truncated, _ = env.step(actions[k])
            wall += time.perf_counter() - start
            totals += batch.counters[0] - before
            if terminated or truncated:
                env.reset()
        wall = wall / CONTROL_STEPS * 1e6
        if wall < best:
            best, counts = wall, totals / CONTROL_STEPS
    idle = np.zeros(1, dtype=np.bool_)
    zero = np.zeros(1)
    dispatch = best_time(lambda n: [batch.step(zero, idle) for _ in range(n)], 3000)
    physics_step = batch.step
    batch.step = lambda a, active=None: physics_step(a, idle)  # the env's Python around no physics
    action = np.zeros(1, np.float32)
    python = best_time(lambda n: [env.step(action) for _ in range(n)], 3000) - dispatch
    batch.step = physics_step
    residual, jacobian, solve = kernel_costs(batch, ENV_FIDELITIES[preset]["dt"] / 2)
    newton = counts[COUNT_NEWTON]
    # an iteration evaluates one residual and solves once; each solve also evaluates the residual of
    # its result, so residuals ~ iterations + one per step
    steps = counts[COUNT_STEPS] + counts[COUNT_REJECTED]
    newton_time = newton * (residual + jacobian + solve) + steps * residual
    rest = max(best - python - dispatch - newton_time, 0.0)
    env.close()
    return {
        "preset": preset,
        "mode": mode,
        "steps_per_s": 1e6 / best,
        "us": best,
        "sim_steps": counts[COUNT_STEPS],
        "rejected": counts[COUNT_REJECTED],
        "impulse": counts[COUNT_IMPULSE_REJECTED],
        "by_reason": counts[COUNT_BY_REASON : COUNT_BY_REASON + len(REJECTIONS)],
        "newton": newton,
        "python": python,
        "dispatch": dispatch,
        "residual": (newton + steps) * residual,
        "jacobian": newton * jacobian,
        "solve": newton * solve,
        "rest": rest,
        "per_iteration": residual + jacobian + solve,
    }


def table(rows):
    reasons = ", ".join(REJECTIONS)
    lines = [
        f"# {ENV_ID}: where an env step's time goes (random actions)",
        "",
        "Per control step: simulator steps accepted, rejected (of which for the contact impulse;",
        f"the others by reason: {reasons}) and Newton iterations.",
        "",
        "| preset | mode | env steps/s | sim steps | rejected (impulse) | by reason | Newton its |",
        "|---|---|---:|---:|---:|---|---:|",
    ]
    for r in rows:
        reasons = " / ".join(f"{x:.2f}" for x in r["by_reason"])
        lines.append(
            f"| {r['preset']} | {r['mode']} | {r['steps_per_s']:,.0f} | {r['sim_steps']:.2f} | "
            f"{r['rejected']:.2f} ({r['impulse']:.2f}) | {reasons} | {r['newton']:.1f} |"
        )
    lines += [
        "",
        "Phases, microseconds per control step (the Newton kernels timed alone at the episode's",
        "state; 'rest' = the remainder: predictor, contact bookkeeping, energy guard, events,",
        "observation and reward):",
        "",
        "| preset | mode | total | Python | dispatch | residuals | Jacobian | factor + solve | rest "
        "| us per Newton iteration |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        lines.append(
            f"| {r['preset']} | {r['mode']} | {r['us']:.0f} | {r['python']:.0f} | {r['dispatch']:.0f} | "
            f"{r['residual']:.0f} | {r['jacobian']:.0f} | {r['solve']:.0f} | {r['rest']:.0f} | "
            f"{r['per_iteration']:.1f} |"
        )
    return "\n".join(lines) + "\n"


def main(argv=None):
    presets = (argv or sys.argv[1:]) or tuple(ENV_FIDELITIES)
    rows = [profile(preset, mode) for preset in presets for mode in MODES]
    reset, first_step, cached_step = compile_times(_COLD_START_SNIPPET)
    text = table(rows) + (
        f"\nCold start (default env, fresh interpreter, empty numba cache): import, make and reset "
        f"{reset:.1f} s, first step {first_step:.1f} s; from the cache: first step {cached_step:.2f} s.\n"
    )
    RESULTS.mkdir(exist_ok=True)
    write_text(RESULTS / "env_profile.md", text)
    print(text)


if __name__ == "__main__":
    main()
