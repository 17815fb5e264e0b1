"""Trained agents against the tuned 3-D dribbler on InflatedBall3DPaddle-v0: SAC runs of train.py
behind the bounce-level task ``agents.wrappers3d.PaddleStrike3D`` (the agent corrects the
dribbler's strike once per flight), each run's best model scored on the same held-out episodes as
the dribbler by ``agents.evaluate3d`` (combined height-and-spot error per episode), the IQM over the
runs' episodes with the stratified bootstrap interval of ``agents.study`` (runs, then episodes
within a run), the learning curves drawn, and a clip of the first run's agent.

    python train.py --algo sac --action-mode paddle3d --conf-file sac_strike3d --seed S \\
        --total-timesteps 6000 --eval-freq 1500 --eval-episodes 3 --final-episodes 0 --log-dir runs
    python benchmarks/ball3d_strike.py runs/sac_paddle3d_seed0 runs/sac_paddle3d_seed1 \\
        runs/sac_paddle3d_seed2 [--episodes 100] [--max-episode-steps 500]
    # writes benchmarks/results/ball3d_strike.md, docs/learning_curve_strike3d.png and
    # docs/figures/strike3d.mp4

The policies are scored in a process each, two at a time (``--workers``); every one sees the
episodes seeded 10,000 on (the training used seeds 0, 1, ... and the periodic evaluations 1000 on).
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import pathlib  # noqa: E402
import re  # noqa: E402
import time  # noqa: E402
from concurrent.futures import ProcessPoolExecutor  # noqa: E402

import numpy as np  # noqa: E402

from agents.study import bootstrap_iqm, iqm  # noqa: E402
from ballenv.files import write_text  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"


def score(
    policy: str, episodes: int, steps: int
) -> tuple[str, tuple[float, ...], tuple[float, ...], tuple[float, ...], float]:
    """``(policy, combined errors, height errors, spot distances (m), wall s)`` of ``episodes``
    held-out episodes of at most ``steps`` control steps."""
    import torch

    torch.set_num_threads(1)
    from agents.evaluate3d import evaluate3d

    start = time.perf_counter()
    s = evaluate3d(policy, {"action_mode": "paddle", "max_episode_steps": steps}, episodes)
    return policy, s.combined_errors, s.height_errors, s.spot_distances, time.perf_counter() - start


def interval(runs: list[tuple[float, ...]]) -> str:
    """``IQM [low, high]`` over the episodes of ``runs`` (a tuple of per-episode values a run)."""
    low, high = bootstrap_iqm([np.asarray(r) for r in runs])
    return f"{iqm(np.concatenate(runs)):.3f} [{low:.3f}, {high:.3f}]"


def compare(reference: list[tuple[float, ...]], runs: list[tuple[float, ...]]) -> str:
    """Whether the trained ``runs``' combined errors are below, above or not apart from the
    dribbler's (``reference``): their 95 % intervals compared."""
    low, high = bootstrap_iqm([np.asarray(r) for r in runs])
    ref_low, ref_high = bootstrap_iqm([np.asarray(r) for r in reference])
    if high < ref_low:
        return "The trained agents beat the dribbler: their interval lies below the dribbler's."
    if low > ref_high:
        return "The dribbler beats the trained agents: their interval lies above the dribbler's."
    return (
        f"The intervals overlap ({low:.3f}-{high:.3f} against {ref_low:.3f}-{ref_high:.3f}): the trained "
        "agents do not beat the dribbler."
    )


def curves(runs: list[pathlib.Path], out: pathlib.Path) -> list[str]:
    """Each run's periodic evaluations (mean return by strikes) as lines of the page, drawn to ``out``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.5))
    lines = []
    for run in runs:
        log = np.load(run / "evaluations.npz")
        means = log["results"].mean(axis=1)
        ax.plot(log["timesteps"], means, marker="o", label=run.name)
        points = ", ".join(f"{int(t)}: {r:.1f}" for t, r in zip(log["timesteps"], means, strict=True))
        state = run / "resume" / "state.json"  # a run stopped by Ctrl-C (train.py) says where
        done = json.loads(state.read_text())["num_timesteps"] if state.exists() else None
        stopped = f"; stopped at {done} strikes" if done else ""
        lines.append(f"- `{run.name}`: {points}{stopped}")
    ax.set_xlabel("strikes (agent steps)")
    ax.set_ylabel("mean evaluation return (env reward)")
    ax.set_title("SAC behind PaddleStrike3D, InflatedBall3DPaddle-v0")
    ax.legend()
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return lines


def clip(run: pathlib.Path, out: pathlib.Path, seconds: float) -> None:
    """A real-time clip (MP4) of ``run``'s best model on held-out episode 10,000."""
    import gymnasium as gym

    import ballenv  # noqa: F401
    from agents.baselines import ModelPolicy
    from ballenv.video import write_video

    env = gym.make("ballenv:InflatedBall3DPaddle-v0", render_mode="rgb_array")
    policy = ModelPolicy(env, run)
    obs, _ = env.reset(seed=10_000)
    policy.reset(10_000)
    frames = [env.render()]
    fps = env.metadata["render_fps"]
    for _ in range(int(seconds * fps)):
        obs, _, terminated, truncated, _ = env.step(policy.act(obs))
        frames.append(env.render())
        if terminated or truncated:
            break
    write_video(frames, out, fps)
    env.close()


def build_parser() -> argparse.ArgumentParser:
    """The command line of ``python benchmarks/ball3d_strike.py``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=pathlib.Path, help="train.py run folders")
    parser.add_argument("--episodes", type=int, default=100, help="held-out episodes per policy")
    parser.add_argument("--max-episode-steps", type=int, default=500, help="time limit (control steps)")
    parser.add_argument("--workers", type=int, default=2, help="policies scored at once")
    parser.add_argument("--clip-seconds", type=float, default=6.0)
    return parser


def main() -> None:
    args = build_parser().parse_args()
    policies = ["heuristic"] + [str(r) for r in args.runs]
    with ProcessPoolExecutor(args.workers) as pool:
        results = list(
            pool.map(
                score, policies, [args.episodes] * len(policies), [args.max_episode_steps] * len(policies)
            )
        )
    dribbler, trained = results[0], results[1:]
    rows = []
    for name, group in (("dribbler (tuned)", [dribbler]), (f"trained ({len(trained)} runs)", trained)):
        rows.append(
            f"| {name} | {sum(len(g[1]) for g in group)} | {interval([g[1] for g in group])} | "
            f"{interval([g[2] for g in group])} | {interval([g[3] for g in group])} | "
            f"{sum(g[4] for g in group):.0f} |"
        )
    for g in trained:
        rows.append(
            f"| {pathlib.Path(g[0]).name} | {len(g[1])} | {interval([g[1]])} | {interval([g[2]])} | "
            f"{interval([g[3]])} | {g[4]:.0f} |"
        )
    curve = curves(args.runs, ROOT / "docs" / "learning_curve_strike3d.png")
    clip(args.runs[0], ROOT / "docs" / "figures" / "strike3d.mp4", args.clip_seconds)
    command = (args.runs[0] / "command.txt").read_text().strip().splitlines()[-1]
    command = re.sub(r"--log-dir \S+", "--log-dir RUNS", "python " + command[command.index("train.py") :])
    verdict = compare([dribbler[1]], [g[1] for g in trained])
    page = [
        "# Trained agents against the 3-D dribbler",
        "",
        f"`python benchmarks/ball3d_strike.py {' '.join('RUNS/' + r.name for r in args.runs)} --episodes "
        f"{args.episodes} --max-episode-steps {args.max_episode_steps}`: "
        f"InflatedBall3DPaddle-v0 (fast preset, 162 vertices), {args.episodes} held-out episodes (seeds "
        f"10000 on) of at most {args.max_episode_steps} control steps per policy.",
        "",
        "Each run is SAC behind `agents.wrappers3d.PaddleStrike3D` (the agent corrects the tuned "
        f"dribbler's strike once per flight), trained by `{command}` with its seed; its best model "
        "(the highest mean return of the periodic evaluations) is scored. Errors per episode as "
        "`agents.evaluate3d` defines them (combined = height error / 0.5 + spot distance / 0.3 m); IQM "
        "over the episodes of all runs, 95 % stratified bootstrap interval (`agents.study.bootstrap_iqm`).",
        "",
        "| policy | episodes | combined error IQM [95 % CI] | height error IQM [95 % CI] | spot "
        "distance IQM [95 % CI] (m) | wall time (s) |",
        "|---|---:|---:|---:|---:|---:|",
        *rows,
        "",
        verdict,
        "",
        "Learning curves: the periodic evaluations' mean return by strikes trained (the env's own "
        "reward summed over an episode of its 1000-step time limit, what picks the best model; "
        "`docs/learning_curve_strike3d.png`):",
        "",
        *curve,
        "",
        f"A clip of `{args.runs[0].name}`'s agent: `docs/figures/strike3d.mp4`.",
        "",
    ]
    write_text(RESULTS / "ball3d_strike.md", "\n".join(page))
    print("\n".join(rows))


if __name__ == "__main__":
    main()
