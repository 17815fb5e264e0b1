"""What the 3-D paddle's score leaves to a strike policy: how much of the tuned dribbler's combined
error on held-out episodes of InflatedBall3DPaddle-v0 (``agents.evaluate3d``) any policy that
strikes where the dribbler strikes could remove, and how much the best correction of each strike
removes when the simulator's future is known.

    python benchmarks/ball3d_headroom.py [--episodes 100] [--oracle-episodes 10] [--max-episode-steps 500]
    # writes benchmarks/results/ball3d_headroom.md (about 15 min on 2 cores)
    python benchmarks/ball3d_headroom.py --target-height-range 0.7 1.0 --start-height-range 0.45 0.65 \
        --out benchmarks/results/ball3d_headroom_low_start.md   # every start below every target

* **Split.** The dribbler plays each held-out episode (seeds 10,000 on, as ``ball3d_strike.py``
  scores); each apex counts as *before* or *after* its first strike. The paddle strikes a falling
  ball downward (``ballenv.envs.ball3d.env``), so it only adds energy: while the ball is too high for
  the target apex the dribbler idles, and those apexes are the same for every policy that does not
  drive a too-high ball higher.
* **Oracle.** At each of the first ``--oracle-strikes`` strikes of ``--oracle-episodes`` episodes,
  each correction of :data:`GRID` (``agents.wrappers3d.PaddleStrike3D``'s actions) is played on a
  copy of the env to the strike's apex; the best one's combined error against the dribbler's own
  (the zero correction). A strike whose episode reaches its time limit before the apex is skipped.
* **Bounds.** Each episode's combined error again with every apex after the first strike perfect,
  and with each one's error times the oracle's ratio of means, as 3 runs of the same episodes
  (``ball3d_strike.py``'s 3 seeds x 100 episodes), each with its IQM and 95 % stratified bootstrap
  interval (``agents.study``).
* **Task.** ``--target-height-range`` and ``--start-height-range`` (m) set the env's keywords of
  those names (the env's defaults otherwise: targets 0.5-1 m, starts 0.6-1.2 m): with every start
  below every target, no apex is too high before a strike has set it.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import copy  # noqa: E402
import pathlib  # noqa: E402
import time  # noqa: E402
from concurrent.futures import ProcessPoolExecutor  # noqa: E402

import numpy as np  # noqa: E402
from numpy.typing import NDArray  # noqa: E402

from agents.study import bootstrap_iqm, iqm  # noqa: E402
from ballenv.files import write_text  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
SEED = 10_000
ENV_ID = "ballenv:InflatedBall3DPaddle-v0"
RUNS = 3  # the trained runs ball3d_strike.py scores, each on the same episodes
# corrections tried at a strike (PaddleStrike3D's actions: impulse, x tilt, y tilt, each in [-1, 1])
GRID = [(0.0, x, y) for x in (-1.0, -0.5, 0.0, 0.5, 1.0) for y in (-1.0, -0.5, 0.0, 0.5, 1.0)] + [
    (s, 0.0, 0.0) for s in (-1.0, -0.5, 0.5, 1.0)
]


class FirstStrike:
    """The tuned dribbler, noting the control step (1-based) of its first strike in an episode."""

    def __init__(self, env) -> None:
        from agents.policies import Heuristic3DPolicy

        self.inner = Heuristic3DPolicy(env)
        self.name = self.inner.name
        self.steps, self.first = 0, None

    def reset(self, seed: int) -> None:
        self.inner.reset(seed)
        self.steps, self.first = 0, None

    def act(self, obs: NDArray[np.float32]) -> NDArray[np.float32]:
        action = self.inner.act(obs)
        self.steps += 1
        if self.first is None and action[0] > -1.0:
            self.first = self.steps
        return action


def split(seed: int, steps: int, task: dict) -> list[tuple[float, float, bool]]:
    """The dribbler's episode ``seed`` of the env with keywords ``task``: each apex's ``(height
    error, spot distance m, after its first strike)``, missed apexes included (``agents.evaluate3d``)."""
    import gymnasium as gym

    from agents.evaluate3d import apex_records

    env = gym.make(ENV_ID, max_episode_steps=steps, **task)
    policy = FirstStrike(env)
    apexes, _, _ = apex_records(env, policy, seed)
    env.close()
    first = policy.first
    return [(a.height, a.distance, first is not None and a.step > first) for a in apexes]


def oracle(seed: int, strikes: int, steps: int, task: dict) -> list[tuple[float, float]]:
    """``(the dribbler's apex error, the best of GRID's)`` at each of the first ``strikes`` strikes of
    episode ``seed`` of the env with keywords ``task`` (module doc)."""
    import gymnasium as gym

    from agents.wrappers3d import PaddleStrike3D

    env = PaddleStrike3D(gym.make(ENV_ID, max_episode_steps=steps, **task))
    env.reset(seed=seed)
    rows = []
    for _ in range(strikes):
        errors = []
        for action in GRID:
            _, reward, _, truncated, _ = copy.deepcopy(env).step(np.array(action, dtype=np.float32))
            errors.append((-float(reward), truncated))
        zero, ended = errors[GRID.index((0.0, 0.0, 0.0))]
        if ended and zero == 0.0:
            break  # the time limit came before the apex
        rows.append((zero, min(e for e, _ in errors)))
        _, _, terminated, truncated, _ = env.step(np.zeros(3, dtype=np.float32))
        if terminated or truncated:
            break
    env.close()
    return rows


def combined(rows: list[tuple[float, float, bool]], factor: float) -> float:
    """An episode's combined error (``agents.evaluate3d``) with the errors of the apexes after the
    first strike times ``factor``."""
    from agents.evaluate3d import combined_error
    from ballenv.envs.ball3d.config import Ball3DConfig

    height = np.mean([h * (factor if after else 1.0) for h, _, after in rows])
    distance = np.mean([d * (factor if after else 1.0) for _, d, after in rows])
    return combined_error(Ball3DConfig(action_mode="paddle"), float(height), float(distance))


def interval(scores: NDArray[np.float64], runs: int) -> str:
    """``IQM [low, high]`` of per-episode ``scores`` counted as ``runs`` runs of the same episodes."""
    low, high = bootstrap_iqm([scores] * runs)
    return f"{iqm(scores):.3f} [{low:.3f}, {high:.3f}]"


def build_parser() -> argparse.ArgumentParser:
    """The command line (module doc)."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--episodes", type=int, default=100, help="held-out episodes of the split (default 100)")
    p.add_argument("--oracle-episodes", type=int, default=10, help="episodes the oracle probes (default 10)")
    p.add_argument("--oracle-strikes", type=int, default=3, help="strikes probed per episode (default 3)")
    p.add_argument("--max-episode-steps", type=int, default=500, help="time limit (default 500)")
    p.add_argument("--workers", type=int, default=2, help="processes (default 2)")
    for name in ("target", "start"):
        p.add_argument(
            f"--{name}-height-range", type=float, nargs=2, metavar=("LOW", "HIGH"),
            help=f"the env's {name}_height_range (m; default the env's)",
        )  # fmt: skip
    p.add_argument("--out", type=pathlib.Path, default=RESULTS / "ball3d_headroom.md")
    return p


def main() -> None:
    args = build_parser().parse_args()
    start = time.perf_counter()
    seeds = range(SEED, SEED + args.episodes)
    probed = range(SEED, SEED + args.oracle_episodes)
    task = {
        f"{name}_height_range": tuple(value)
        for name in ("target", "start")
        if (value := getattr(args, f"{name}_height_range")) is not None
    }
    with ProcessPoolExecutor(args.workers) as pool:
        limit = args.max_episode_steps
        episodes = list(pool.map(split, seeds, [limit] * len(seeds), [task] * len(seeds)))
        strikes = pool.map(
            oracle, probed, [args.oracle_strikes] * len(probed), [limit] * len(probed), [task] * len(probed)
        )
        probes = np.array([row for rows in strikes for row in rows])
    ratio = float(probes[:, 1].mean() / probes[:, 0].mean())
    dribbler = np.array([combined(rows, 1.0) for rows in episodes])
    best = np.array([combined(rows, ratio) for rows in episodes])
    perfect = np.array([combined(rows, 0.0) for rows in episodes])
    before = np.mean([sum(not after for *_, after in rows) for rows in episodes])
    apexes = np.mean([len(rows) for rows in episodes])
    share = 1.0 - perfect.sum() / dribbler.sum()
    low = bootstrap_iqm([dribbler])[0]
    options = "".join(f" --{key.replace('_', '-')} {lo:g} {hi:g}" for key, (lo, hi) in task.items())
    keywords = ", ".join(f"`{key}={lo:g}-{hi:g} m`" for key, (lo, hi) in task.items())
    clean = np.mean([all(after for *_, after in rows) for rows in episodes])
    page = [
        "# The 3-D paddle: what the score leaves to a strike policy" + (f" ({keywords})" if task else ""),
        "",
        f"`python benchmarks/ball3d_headroom.py --episodes {args.episodes} --oracle-episodes "
        f"{args.oracle_episodes} --oracle-strikes {args.oracle_strikes} --max-episode-steps "
        f"{args.max_episode_steps}{options}`: InflatedBall3DPaddle-v0 (fast preset, 162 vertices"
        + (f"; {keywords}" if task else "")
        + "), the tuned "
        f"dribbler on {args.episodes} held-out episodes (seeds {SEED} on) of at most "
        f"{args.max_episode_steps} control steps; the method is the script's docstring. "
        f"{time.perf_counter() - start:.0f} s on {args.workers} processes.",
        "",
        f"**Split.** {apexes:.2f} apexes an episode, {before:.2f} of them before the dribbler's first "
        f"strike, which hold {1 - share:.0%} of its combined error (the apexes after it: {share:.0%}); "
        f"{clean:.0%} of the episodes have none before it.",
        "",
        f"**Oracle.** {len(probes)} strikes of {args.oracle_episodes} episodes: the combined error of "
        f"the strike's apex {probes[:, 0].mean():.3f} with the dribbler's strike, {probes[:, 1].mean():.3f} "
        f"with the best of {len(GRID)} corrections (ratio of means {ratio:.2f}).",
        "",
        "| policy | episodes | combined error IQM [95 % CI] |",
        "|---|---:|---:|",
        f"| dribbler (tuned) | {args.episodes} | {interval(dribbler, 1)} |",
        f"| every apex after the first strike at the oracle's ratio, as {RUNS} runs | {RUNS * args.episodes} "
        f"| {interval(best, RUNS)} |",
        f"| every apex after the first strike perfect, as {RUNS} runs | {RUNS * args.episodes} "
        f"| {interval(perfect, RUNS)} |",
        "",
        verdict(low, bootstrap_iqm([best] * RUNS)[1], bootstrap_iqm([perfect] * RUNS)[1]),
    ]
    write_text(args.out, "\n".join(page) + "\n")
    print("\n".join(page))


def verdict(dribbler_low: float, best_high: float, perfect_high: float) -> str:
    """Whether each bound's interval lies below the dribbler's (``ball3d_strike.py``'s test)."""

    def apart(high: float) -> str:
        return "below" if high < dribbler_low else "not below"

    return (
        f"The dribbler's interval starts at {dribbler_low:.3f}. The oracle bound's ends at {best_high:.3f} "
        f"({apart(best_high)} it); the perfect bound's at {perfect_high:.3f} ({apart(perfect_high)} it)."
    )


if __name__ == "__main__":
    main()
