"""Throughput of InflatedBall-v3: env steps per second per fidelity preset and action mode, the native
vector env against Gymnasium's SyncVectorEnv, and each preset's first-apex error.

    python benchmarks/env_throughput.py    # writes benchmarks/results/env_throughput.md and .png
    python benchmarks/env_throughput.py --vector    # prints the vector table alone

Single process, numba warm (one warm-up episode), OPENBLAS_NUM_THREADS=1. Policies: "scripted" is
the heuristic controller of the mode (a ball that keeps bouncing: the workload of a trained agent),
"random" draws uniform actions (a learner's first episodes; violent for the pressure mode, whose
random pumping rings the ball). Steps/s counts env steps including resets; best of 3 repeats.

Preset error: first apex of a ball (R = 0.12 m, E = 10 MPa, h = 2 mm, 30 kPa, friction 0.5) dropped
from 1 m, against a reference at N = 128, dt <= 1e-3 s, impulse_tol = 1e-4 N s.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pathlib  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import gymnasium as gym  # noqa: E402
import numba  # noqa: E402
import numpy as np  # noqa: E402
from tqdm.auto import tqdm  # noqa: E402

import ballenv  # noqa: E402, F401
from ballenv.controllers import PaddleDribble, PressurePump  # noqa: E402
from ballenv.envs.numerics import ENV_FIDELITIES, with_env_fidelity  # noqa: E402
from ballenv.files import write_text  # noqa: E402
from ballenv.physics import Ground, Ring, Scene, simulate  # noqa: E402
from ballenv.physics.base.ring import total_mass  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
PRESETS = tuple(ENV_FIDELITIES)
MODES = ("pressure", "paddle")
SINGLE_STEPS = 2000
VECTOR_SIZES = (1, 8, 64)
VECTOR_KINDS = ("native, 1 thread", "native, all threads", "SyncVectorEnv")
VECTOR_ENV_STEPS = 6400  # env steps per vector measurement (split over the envs)


def controller(env, mode, structure):
    config = env.unwrapped.config
    if mode == "pressure":
        return PressurePump(structure)
    mass = total_mass(config.ring(config.initial_pressure))
    return PaddleDribble(structure, mass, max_impulse=config.paddle_max_impulse)


def single_rate(preset, mode, policy, repeats=3):
    env = gym.make("InflatedBall-v3", action_mode=mode, fidelity=preset)
    obs, info = env.reset(seed=0)
    ctrl = controller(env, mode, env.unwrapped.observation_structure)
    env.action_space.seed(0)
    for _ in range(50):  # warm-up (compiles on the first run)
        obs, *_ = env.step(env.action_space.sample())
    best = 0.0
    for rep in range(repeats):
        obs, _ = env.reset(seed=rep)
        ctrl.reset()
        start = time.perf_counter()
        for _ in range(SINGLE_STEPS):
            action = env.action_space.sample() if policy == "random" else ctrl.act(obs)
            obs, _, terminated, truncated, _ = env.step(action)
            if terminated or truncated:
                obs, _ = env.reset()
                ctrl.reset()
        best = max(best, SINGLE_STEPS / (time.perf_counter() - start))
    return best


def vector_envs(n_envs, mode):
    """The three vector envs compared: the native one on one thread and on all, and SyncVectorEnv."""

    def native(threads):
        return gym.make_vec(
            "InflatedBall-v3", num_envs=n_envs, vectorization_mode="vector_entry_point", action_mode=mode,
            num_threads=threads,
        )  # fmt: skip

    sync = gym.make_vec("InflatedBall-v3", num_envs=n_envs, vectorization_mode="sync", action_mode=mode)
    return dict(zip(VECTOR_KINDS, (native(1), native(None), sync), strict=True))


def vector_rates(n_envs, mode, repeats=3):
    """Env steps/s of each of :func:`vector_envs`, best of ``repeats``; each repeat runs the same
    seeds and actions through all of them, one after the other (the machine's drifts hit all)."""
    venvs = vector_envs(n_envs, mode)
    steps = max(1, VECTOR_ENV_STEPS // n_envs)
    best = dict.fromkeys(venvs, 0.0)
    for rep in range(-1, repeats):  # rep -1: warm-up
        actions = np.random.default_rng(rep + 1).uniform(-1, 1, (steps, n_envs, 1)).astype(np.float32)
        for name, venv in venvs.items():
            venv.reset(seed=rep + 1)
            start = time.perf_counter()
            for a in actions if rep >= 0 else actions[:5]:
                venv.step(a)
            if rep >= 0:
                best[name] = max(best[name], steps * n_envs / (time.perf_counter() - start))
    for venv in venvs.values():
        venv.close()
    return best


def vector_measurements():
    """{(mode, envs): rates of :func:`vector_rates`}."""
    return {
        (mode, n): vector_rates(n, mode) for mode in MODES for n in tqdm(VECTOR_SIZES, desc=f"vector {mode}")
    }


def vector_table(vector):
    threads = numba.get_num_threads()
    lines = [
        "",
        f"Vector envs, fast preset, random actions (env steps/s, all envs together; all threads = "
        f"{threads}):",
        "",
        "| mode | envs | native, 1 thread | native, all threads | SyncVectorEnv | threads speed-up | "
        "native / Sync |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for (mode, n), rate in vector.items():
        one, every, sync = (rate[name] for name in VECTOR_KINDS)
        rates = f"{one:,.0f} | {every:,.0f} | {sync:,.0f}"
        lines.append(f"| {mode} | {n} | {rates} | {every / one:.2f} | {every / sync:.2f} |")
    return lines


def drop_scene():
    ring = Ring(
        radius=0.12, n_nodes=64, youngs_modulus=10e6, thickness=2e-3, pressure=30e3, position=(0.0, 1.0)
    )
    return Scene(rings=[ring], grounds=[Ground(friction=0.5)])


def preset_errors():
    """{preset: (first apex m, relative error, wall s)} and the reference apex."""
    base = drop_scene()
    reference_scene = with_env_fidelity(base, "accurate")
    reference_scene = reference_scene.__class__(
        **{**reference_scene.__dict__, "dt": 1e-3, "impulse_tol": 1e-4, "newton_tol": 1e-10}
    )
    reference = simulate(reference_scene, 0.9).apexes()[0, 1]
    out = {}
    for preset in PRESETS:
        sc = with_env_fidelity(base, preset)
        simulate(sc, 0.05)
        walls = []
        for _ in range(3):
            traj = simulate(sc, 0.9)
            walls.append(traj.stats.wall_time)
        apex = traj.apexes()[0, 1]
        out[preset] = (apex, abs(apex - reference) / reference, float(np.median(walls)))
    return out, reference


def main():
    RESULTS.mkdir(exist_ok=True)
    lines = [
        "# InflatedBall-v3 throughput",
        "",
        f"Single env, {SINGLE_STEPS} steps, best of 3 (env steps/s):",
        "",
    ]
    lines += ["| preset | mode | scripted policy | random actions |", "|---|---|---:|---:|"]
    single = {}
    for preset in tqdm(PRESETS, desc="single env"):
        for mode in MODES:
            single[preset, mode] = (
                single_rate(preset, mode, "scripted"),
                single_rate(preset, mode, "random"),
            )
            s, r = single[preset, mode]
            lines.append(f"| {preset} | {mode} | {s:,.0f} | {r:,.0f} |")
    lines += vector_table(vector := vector_measurements())
    errors, reference = preset_errors()
    lines += ["", f"Preset first-apex error (drop from 1 m; reference apex {reference:.5f} m):", ""]
    lines += [
        "| preset | nodes | first apex (m) | relative error | wall for 0.9 s (ms) |",
        "|---|---:|---:|---:|---:|",
    ]
    for preset, (apex, err, wall) in errors.items():
        nodes = ENV_FIDELITIES[preset]["n_nodes"]
        lines.append(f"| {preset} | {nodes} | {apex:.5f} | {err:.2%} | {wall * 1e3:.1f} |")
    text = "\n".join(lines) + "\n"
    write_text(RESULTS / "env_throughput.md", text)
    print(text)
    plot(single, vector)


def plot(single, vector):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    x = np.arange(len(PRESETS))
    for k, mode in enumerate(MODES):
        left.bar(
            x + 0.2 * (2 * k - 1), [single[p, mode][0] for p in PRESETS], 0.4, label=f"{mode} (scripted)"
        )
    left.set_xticks(x, PRESETS)
    left.set_ylabel("env steps / s (single process)")
    left.set_yscale("log")
    left.legend()
    for mode in MODES:
        for name, style in zip(VECTOR_KINDS, ("^:", "o-", "s--"), strict=True):
            rates = [vector[mode, n][name] for n in VECTOR_SIZES]
            right.plot(VECTOR_SIZES, rates, style, label=f"{name}, {mode}")
    right.set_xscale("log")
    right.set_xlabel("envs")
    right.set_ylabel("env steps / s (random actions)")
    right.legend()
    fig.tight_layout()
    fig.savefig(RESULTS / "env_throughput.png", dpi=120)


if __name__ == "__main__":
    if sys.argv[1:] == ["--vector"]:  # the vector table alone
        print("\n".join(vector_table(vector_measurements())))
    else:
        main()
