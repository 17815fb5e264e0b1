"""The scripted 3-D dribbler (``ballenv.controllers.PaddleDribble3D`` with its tuned parameters)
against a paddle that never strikes and against random actions, on InflatedBall3DPaddle-v0's held-out
episodes: the combined height-and-spot error of ``agents.evaluate3d``, with IQMs and bootstrap
intervals (``agents.study``). With ``--action-mode pressure``, the same for the pump
(``PressurePump3D``) against constant gas and random actions on InflatedBall3D-v0.

    python benchmarks/ball3d_dribbler.py [--episodes 20] [--max-episode-steps 1000]
    # writes benchmarks/results/ball3d_dribbler.md
    python benchmarks/ball3d_dribbler.py --action-mode pressure --episodes 10
    # writes benchmarks/results/ball3d_pump.md
    python benchmarks/ball3d_dribbler.py --model runs/ppo_paddle3d_seed0
    # also a trained model (a train.py run's best model) and its learning curve

One process, one core (run it under ``taskset -c 1`` on a shared machine), OPENBLAS_NUM_THREADS=1.
Episodes seeded 10,000 on (the tuning used seeds 0, 1, ...); every policy sees the same episodes.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import pathlib  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

import ballenv  # noqa: E402, F401
from agents.config import tuned_heuristic3d  # noqa: E402
from agents.evaluate3d import DEFAULT_SEED, Score3D, evaluate3d  # noqa: E402
from agents.study import bootstrap_iqm, iqm  # noqa: E402
from ballenv.files import write_text  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
POLICIES = ("heuristic", "idle", "random")  # the tuned dribbler, no strike, random actions


def interval(values: tuple[float, ...]) -> str:
    """``IQM [low, high]`` of one policy's per-episode ``values`` (the episodes as one run)."""
    low, high = bootstrap_iqm([np.asarray(values)])
    return f"{iqm(values):.3f} [{low:.3f}, {high:.3f}]"


def row(score: Score3D, seconds: float) -> str:
    """One table row of ``score`` (its wall time ``seconds``)."""
    return (
        f"| {score.policy} | {len(score.lengths)} | {interval(score.combined_errors)} | "
        f"{interval(score.height_errors)} | {interval(score.spot_distances)} | "
        f"{np.mean(score.apexes):.1f} | {np.mean(score.lengths):.0f} | {np.mean(score.returns):.1f} "
        f"| {seconds:.0f} |"
    )


def learning_curve(run: pathlib.Path) -> list[str]:
    """The lines that describe the train.py run ``run``: its command and periodic evaluations."""
    log = np.load(run / "evaluations.npz")
    command = (run / "command.txt").read_text().strip().splitlines()[-1]
    command = "python " + command[command.index("train.py") :]
    means = log["results"].mean(axis=1)
    points = ", ".join(f"{int(t) // 1000}k: {r:.0f}" for t, r in zip(log["timesteps"], means, strict=True))
    return [
        f"The trained row is the best model of `{command}` (periodic evaluations of "
        f"{log['results'].shape[1]} episodes; the best is the one with the highest mean return). Its "
        f"learning curve, mean return by env steps: {points}.",
        "",
    ]


def page(rows: list[str], args: argparse.Namespace) -> str:
    params = ", ".join(f"{k} = {v}" for k, v in sorted(tuned_heuristic3d(args.action_mode).items()))
    paddle = args.action_mode == "paddle"
    lines = [
        "# The scripted 3-D dribbler" if paddle else "# The scripted 3-D pump",
        "",
        f"`python benchmarks/ball3d_dribbler.py{'' if paddle else ' --action-mode pressure'}"
        f"{f' --model {args.model}' if args.model else ''} --episodes "
        f"{args.episodes} --max-episode-steps {args.max_episode_steps}`: "
        f"{'InflatedBall3DPaddle-v0' if paddle else 'InflatedBall3D-v0'} (fast preset, 162 vertices), "
        f"{args.episodes} held-out episodes (seeds {DEFAULT_SEED} on) of at most "
        f"{args.max_episode_steps} control steps ({args.max_episode_steps / 100:.0f} s) per policy, "
        "one core.",
        "",
        "Per episode (`agents.evaluate3d`): the height error is the mean over its flight apexes of",
        "`|h - h_t| / h_t`; the spot distance the mean horizontal distance (m) of the centre to the",
        "target spot at those apexes; the combined error `height error / 0.5 + spot distance / 0.3 m`",
        "(each in units of the reward's margin for it). An apex missed because the ball came to rest",
        "early counts a height error of 1 and the distance where it stopped. IQM over the episodes",
        "with its 95 % bootstrap interval (`agents.study.bootstrap_iqm`, 2,000 resamples).",
        *(
            []
            if paddle
            else ["In pressure mode there is no spot: the combined error is `height error / 0.5`."]
        ),
        "",
        "| policy | episodes | combined error IQM [95 % CI] | height error IQM [95 % CI] | spot "
        "distance IQM [95 % CI] (m) | apexes per episode | episode length (steps) | return | wall time (s) |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
        *rows,
        "",
        f"The {'dribbler' if paddle else 'pump'}'s parameters (`agents/hyperparams/heuristic.yml`, tuned by "
        f"`python -m agents.tune heuristic3d`): {params or 'its defaults'}.",
        "",
        *(learning_curve(args.model) if args.model else []),
    ]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=20, help="held-out episodes per policy")
    parser.add_argument("--max-episode-steps", type=int, default=1000, help="time limit (control steps)")
    parser.add_argument("--action-mode", choices=("paddle", "pressure"), default="paddle")
    parser.add_argument("--model", type=pathlib.Path, default=None, help="a train.py run folder to score too")
    parser.add_argument(
        "--out", type=pathlib.Path, default=None, help="default: results/ball3d_{dribbler,pump}.md"
    )
    args = parser.parse_args()
    args.out = args.out or RESULTS / (
        "ball3d_dribbler.md" if args.action_mode == "paddle" else "ball3d_pump.md"
    )
    kwargs = {"action_mode": args.action_mode, "max_episode_steps": args.max_episode_steps}
    rows = []
    for name in POLICIES + ((str(args.model),) if args.model else ()):
        start = time.perf_counter()
        score = evaluate3d(name, kwargs, args.episodes)
        rows.append(row(score, time.perf_counter() - start))
        print(rows[-1], flush=True)
    write_text(args.out, page(rows, args))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
