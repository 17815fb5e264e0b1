"""The scripted 3-D dribbler (``ballenv.controllers.PaddleDribble3D`` with its tuned parameters)
against a paddle that never strikes and against random actions, on InflatedBall3DPaddle-v0's held-out
episodes: the combined height-and-spot error of ``agents.evaluate3d``, with IQMs and bootstrap
intervals (``agents.study``).

    python benchmarks/ball3d_dribbler.py [--episodes 20] [--max-episode-steps 1000]
    # writes benchmarks/results/ball3d_dribbler.md

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


def page(rows: list[str], args: argparse.Namespace) -> str:
    params = ", ".join(f"{k} = {v}" for k, v in sorted(tuned_heuristic3d("paddle").items())) or "defaults"
    lines = [
        "# The scripted 3-D dribbler",
        "",
        f"`python benchmarks/ball3d_dribbler.py --episodes {args.episodes} --max-episode-steps "
        f"{args.max_episode_steps}`: InflatedBall3DPaddle-v0 (fast preset, 162 vertices), "
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
        "",
        "| policy | episodes | combined error IQM [95 % CI] | height error IQM [95 % CI] | spot "
        "distance IQM [95 % CI] (m) | apexes per episode | episode length (steps) | return | wall time (s) |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
        *rows,
        "",
        f"The dribbler's parameters (`agents/hyperparams/heuristic.yml`, tuned by `python -m agents.tune "
        f"heuristic3d`): {params}.",
        "",
    ]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=20, help="held-out episodes per policy")
    parser.add_argument("--max-episode-steps", type=int, default=1000, help="time limit (control steps)")
    parser.add_argument("--out", type=pathlib.Path, default=RESULTS / "ball3d_dribbler.md")
    args = parser.parse_args()
    kwargs = {"action_mode": "paddle", "max_episode_steps": args.max_episode_steps}
    rows = []
    for name in POLICIES:
        start = time.perf_counter()
        score = evaluate3d(name, kwargs, args.episodes)
        rows.append(row(score, time.perf_counter() - start))
        print(rows[-1], flush=True)
    write_text(args.out, page(rows, args))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
