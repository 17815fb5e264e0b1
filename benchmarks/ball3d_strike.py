"""Trained agents against the tuned 3-D dribbler on InflatedBall3DPaddle-v0: SAC runs of train.py
behind the bounce-level task ``agents.wrappers3d.PaddleStrike3D`` (the agent corrects the
dribbler's strike once per flight), each run's model (``--model``: the best of its periodic
evaluations, or the final one) scored on the same held-out episodes as the dribbler by
``agents.evaluate3d`` (combined height-and-spot error per episode), the IQM over the runs' episodes
with the stratified bootstrap interval of ``agents.study`` (runs, then episodes within a run), the
learning curves drawn, and a clip of the first run's agent. Every policy plays the task the runs
trained on: the env keywords of their ``config.yml`` (``env_kwargs``, which must agree).

    python train.py --algo sac --action-mode paddle3d --conf-file sac_strike3d --seed S \\
        --total-timesteps 6000 --eval-freq 1500 --eval-episodes 3 --final-episodes 0 --log-dir runs
    python benchmarks/ball3d_strike.py runs/sac_paddle3d_seed0 runs/sac_paddle3d_seed1 \\
        runs/sac_paddle3d_seed2 [--episodes 100] [--max-episode-steps 500] [--model final] [--tag T]
    # writes benchmarks/results/ball3d_strike.md, docs/learning_curve_strike3d.png and
    # docs/figures/strike3d.mp4 (with --tag T: ball3d_strike_T.md, learning_curve_strike3d_T.png
    # and strike3d_T.mp4)

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
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402
import yaml  # noqa: E402

from agents.study import bootstrap_iqm, iqm  # noqa: E402
from ballenv.files import write_text  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"


def score(
    policy: str, episodes: int, steps: int, task: dict[str, Any]
) -> tuple[str, tuple[float, ...], tuple[float, ...], tuple[float, ...], float]:
    """``(policy, combined errors, height errors, spot distances (m), wall s)`` of ``episodes``
    held-out episodes of at most ``steps`` control steps of the env of keywords ``task``."""
    import torch

    torch.set_num_threads(1)
    from agents.evaluate3d import evaluate3d

    start = time.perf_counter()
    s = evaluate3d(policy, {"action_mode": "paddle", "max_episode_steps": steps, **task}, episodes)
    return policy, s.combined_errors, s.height_errors, s.spot_distances, time.perf_counter() - start


def run_task(runs: list[pathlib.Path]) -> dict[str, Any]:
    """The env keywords the ``runs`` trained on (their ``config.yml``'s ``env_kwargs`` but the action
    mode), which must be the same for all of them."""
    tasks = []
    for run in runs:
        kwargs = yaml.safe_load((run / "config.yml").read_text()).get("env_kwargs") or {}
        tasks.append({k: v for k, v in kwargs.items() if k != "action_mode"})
    if any(t != tasks[0] for t in tasks):
        raise ValueError(
            f"runs = {[r.name for r in runs]} trained on different env keywords {tasks}: must agree"
        )
    return tasks[0]


def model_path(run: pathlib.Path, model: str) -> pathlib.Path:
    """The saved model of ``run`` to score: ``best_model.zip`` (the run folder) or ``model.zip``."""
    return run if model == "best" else run / "model.zip"


def task_words(task: dict[str, Any]) -> str:
    """``task`` as the page's words, e.g. ``; target_height_range=0.7-0.9 m``."""
    words = [
        f"{k}={v[0]:g}-{v[1]:g} m" if k.endswith("height_range") else f"{k}={v}" for k, v in task.items()
    ]
    return "".join(f"; `{w}`" for w in words)


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


def curves(runs: list[pathlib.Path], out: pathlib.Path, task: str = "") -> list[str]:
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
        # a run stopped by Ctrl-C (train.py) has no final model; its resumable state says where
        state, stopped = run / "resume" / "state.json", not (run / "model.zip").exists()
        done = json.loads(state.read_text())["num_timesteps"] if state.exists() and stopped else None
        stopped = f"; stopped at {done} strikes" if done else ""
        lines.append(f"- `{run.name}`: {points}{stopped}")
    ax.set_xlabel("strikes (agent steps)")
    ax.set_ylabel("mean evaluation return (env reward)")
    ax.set_title(f"SAC behind PaddleStrike3D, InflatedBall3DPaddle-v0{task}", fontsize=9)
    ax.legend()
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return lines


def clip(run: pathlib.Path, out: pathlib.Path, seconds: float, task: dict[str, Any]) -> None:
    """A real-time clip (MP4) of the model ``run`` (a run folder: its best) on held-out episode
    10,000 of the env of keywords ``task``."""
    import gymnasium as gym

    import ballenv  # noqa: F401
    from agents.baselines import ModelPolicy
    from ballenv.video import write_video

    env = gym.make("ballenv:InflatedBall3DPaddle-v0", render_mode="rgb_array", **task)
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
    parser.add_argument(
        "--model", choices=("best", "final"), default="best",
        help="each run's model scored: the best of its periodic evaluations, or the final one",
    )  # fmt: skip
    parser.add_argument("--tag", default="", help="names the page and figures ball3d_strike_TAG.md, ...")
    return parser


def main() -> None:
    args = build_parser().parse_args()
    task, suffix = run_task(args.runs), f"_{args.tag}" if args.tag else ""
    policies = ["heuristic"] + [str(model_path(r, args.model)) for r in args.runs]
    n = len(policies)
    with ProcessPoolExecutor(args.workers) as pool:
        results = list(
            pool.map(score, policies, [args.episodes] * n, [args.max_episode_steps] * n, [task] * n)
        )
    dribbler, trained = results[0], results[1:]
    rows = []
    for name, group in (("dribbler (tuned)", [dribbler]), (f"trained ({len(trained)} runs)", trained)):
        rows.append(
            f"| {name} | {sum(len(g[1]) for g in group)} | {interval([g[1] for g in group])} | "
            f"{interval([g[2] for g in group])} | {interval([g[3] for g in group])} | "
            f"{sum(g[4] for g in group):.0f} |"
        )
    for run, g in zip(args.runs, trained, strict=True):
        rows.append(
            f"| {run.name} | {len(g[1])} | {interval([g[1]])} | {interval([g[2]])} | "
            f"{interval([g[3]])} | {g[4]:.0f} |"
        )
    curve_png, clip_mp4 = f"docs/learning_curve_strike3d{suffix}.png", f"docs/figures/strike3d{suffix}.mp4"
    curve = curves(args.runs, ROOT / curve_png, task_words(task).replace("`", ""))
    clip(model_path(args.runs[0], args.model), ROOT / clip_mp4, args.clip_seconds, task)
    command = (args.runs[0] / "command.txt").read_text().strip().splitlines()[-1]
    command = re.sub(r"--log-dir \S+", "--log-dir RUNS", "python " + command[command.index("train.py") :])
    verdict = compare([dribbler[1]], [g[1] for g in trained])
    options = (f" --model {args.model}" if args.model != "best" else "") + (
        f" --tag {args.tag}" if args.tag else ""
    )
    chosen = (
        "its best model (the highest mean return of the periodic evaluations)" if args.model == "best"
        else "its final model"
    )  # fmt: skip
    page = [
        "# Trained agents against the 3-D dribbler" + (f" ({args.tag})" if args.tag else ""),
        "",
        f"`python benchmarks/ball3d_strike.py {' '.join('RUNS/' + r.name for r in args.runs)} --episodes "
        f"{args.episodes} --max-episode-steps {args.max_episode_steps}{options}`: "
        f"InflatedBall3DPaddle-v0 (fast preset, 162 vertices{task_words(task)}), {args.episodes} held-out "
        f"episodes (seeds 10000 on) of at most {args.max_episode_steps} control steps per policy.",
        "",
        "Each run is SAC behind `agents.wrappers3d.PaddleStrike3D` (the agent corrects the tuned "
        f"dribbler's strike once per flight), trained by `{command}` with its seed; {chosen} is scored. "
        "Errors per episode as `agents.evaluate3d` defines them (combined = height error / 0.5 + spot "
        "distance / 0.3 m); IQM over the episodes of all runs, 95 % stratified bootstrap interval "
        "(`agents.study.bootstrap_iqm`).",
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
        f"`{curve_png}`):",
        "",
        *curve,
        "",
        f"A clip of `{args.runs[0].name}`'s agent: `{clip_mp4}`.",
        "",
    ]
    write_text(RESULTS / f"ball3d_strike{suffix}.md", "\n".join(page))
    print("\n".join(rows))


if __name__ == "__main__":
    main()
