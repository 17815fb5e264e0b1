"""Score a policy on InflatedBall-v3 over held-out episodes.

    ballenv-evaluate heuristic --action-mode pressure --episodes 20   # or python -m agents.evaluate
    python -m agents.evaluate random --action-mode paddle
    python -m agents.evaluate runs/ppo_pressure_seed0          # a run folder of train.py
    python -m agents.evaluate path/to/model.zip --algo sac --env-kwargs '{"action_mode": "paddle"}'

Episode ``k`` is reset with seed ``seed + k`` (default 10,000 on: training uses small seeds), so
the same arguments give the same numbers. Without ``--env-kwargs``, a run folder is scored on the
env it trained on, ``random`` and ``heuristic`` on the task of their mode (the ``env_kwargs`` of
``agents/hyperparams/ppo.yml``, :func:`agents.config.task_env_kwargs`).

Metrics (the reward is the env's training signal; these are the task's measures):

* **apex error**: per episode, the mean of ``|h - h_target| / h_target`` over its flight apexes,
  where each apex missed because the episode ended early (the ball came to rest, left the arena or
  the simulator failed) counts as an error of 1: one per flight time ``2 sqrt(2 (h_target - R) /
  g)`` left until the time limit; reported as the mean over episodes with a 95 % confidence interval
  from Student's t, ``t_{0.975, n-1} s / sqrt(n)`` (:func:`t_quantile`; 12.7 s / sqrt(2) for two
  episodes, 2.26 s / sqrt(10) for ten, where the normal approximation's 1.96 was too narrow);
* **success rate**: the fraction of all apexes (missed ones included) within 5 % of the target;
* **apexes per episode** (missed ones included), **episode length** in control steps, and the mean
  return.
"""

from __future__ import annotations

import argparse
import json
import math
import os
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass
from statistics import NormalDist
from typing import Any, Protocol

import gymnasium as gym
import numpy as np

from ballenv.envs.inflated_ball import ball_env
from ballenv.files import write_text

from .baselines import NAMED_POLICIES, make_policy
from .config import ENV_ID, SUCCESS_TOLERANCE, parse_env_kwargs, task_env_kwargs
from .policies import Policy

DEFAULT_SEED = 10_000


@dataclass(frozen=True)
class Score:
    """Evaluation of one policy; errors are relative to the target apex height."""

    policy: str
    episodes: int
    apex_error: float  # mean over episodes
    apex_error_ci95: float  # half-width of its 95 % confidence interval
    success_rate: float  # apexes within SUCCESS_TOLERANCE, of all apexes (missed ones included)
    episode_length: float  # mean, control steps
    episode_return: float  # mean
    apexes: float  # mean per episode, missed ones included
    episode_apex_errors: tuple[float, ...] = ()  # each episode's apex error, in seed order
    episode_successes: tuple[int, ...] = ()  # each episode's apexes within SUCCESS_TOLERANCE
    episode_apexes: tuple[int, ...] = ()  # each episode's apexes, missed ones included


def run_episode(env: gym.Env[Any, Any], policy: Policy, seed: int) -> tuple[list[float], int, int, float]:
    """One episode; returns (relative apex errors, missed apexes, length, return)."""
    obs, _ = env.reset(seed=seed)
    policy.reset(seed)
    config = ball_env(env).config
    limit = env.spec.max_episode_steps if env.spec and env.spec.max_episode_steps else None
    errors = []
    total = 0.0
    length = 0
    missed = 0
    while True:
        obs, reward, terminated, truncated, info = env.step(policy.act(obs))
        total += float(reward)
        length += 1
        if info["apex_count"]:
            errors.append(abs(info["apex_height"] - info["target_height"]) / info["target_height"])
        if terminated and limit:
            missed = missed_apexes(config, info["target_height"], (limit - length) * config.control_dt)
        if terminated or truncated:
            return errors, missed, length, total


class Bouncing(Protocol):
    """What :func:`missed_apexes` reads of an env's config (the ring's or the 3-D ball's)."""

    @property
    def radius(self) -> float: ...  # m

    @property
    def gravity(self) -> float: ...  # m/s^2


def missed_apexes(config: Bouncing, target: float, time_left: float) -> int:
    """Apexes a ball bouncing to ``target`` (m) would reach in ``time_left`` (s): one per flight
    time ``2 sqrt(2 (target - R) / g)``, ``R`` the unstretched radius (the centre of a resting ball
    is about that high)."""
    flight = 2.0 * math.sqrt(2.0 * max(target - config.radius, 1e-3) / config.gravity)
    return int(round(max(time_left, 0.0) / flight))


def evaluate(
    policy: str | os.PathLike[str] | Callable[[gym.Env[Any, Any]], Policy],
    env_kwargs: Mapping[str, Any] | None = None,
    episodes: int = 20,
    seed: int = DEFAULT_SEED,
    algo: str | None = None,
    progress: bool = False,
    trust: bool = False,
) -> Score:
    """Score ``policy`` (one of ``NAMED_POLICIES``, a saved model / run folder, or a callable ``env ->
    policy``) over ``episodes`` episodes of ``gym.make(ENV_ID, **env_kwargs)`` seeded ``seed, seed +
    1, ...``. A saved model is loaded only if this user's training signed it, or with ``trust``
    (:mod:`agents.signatures`)."""
    env = gym.make(ENV_ID, **(env_kwargs or {}))
    agent = make_policy(policy, env, algo, trust)
    per_episode, hits, apexes, lengths, returns = [], [], [], [], []
    seeds: Iterable[int] = range(seed, seed + episodes)
    if progress:
        from tqdm.auto import tqdm

        seeds = tqdm(seeds, desc=f"evaluate {agent.name}", unit="episode")
    for s in seeds:
        errors, missed, length, total = run_episode(env, agent, s)
        count = len(errors) + missed
        per_episode.append((sum(errors) + missed) / count if count else 1.0)
        hits.append(sum(e <= SUCCESS_TOLERANCE for e in errors))
        apexes.append(count)
        lengths.append(length)
        returns.append(total)
    env.close()
    err = np.array(per_episode)
    n = len(err)
    half = t_quantile(0.975, n - 1) * err.std(ddof=1) / math.sqrt(n) if n > 1 else math.nan
    return Score(
        policy=agent.name if policy in NAMED_POLICIES or callable(policy) else str(policy),
        episodes=episodes,
        apex_error=float(err.mean()),
        apex_error_ci95=float(half),
        success_rate=sum(hits) / sum(apexes) if sum(apexes) else 0.0,
        episode_length=float(np.mean(lengths)),
        episode_return=float(np.mean(returns)),
        apexes=sum(apexes) / episodes,
        episode_apex_errors=tuple(float(e) for e in err),
        episode_successes=tuple(int(h) for h in hits),
        episode_apexes=tuple(int(a) for a in apexes),
    )


def t_probability(t: float, df: int) -> float:
    """``P(|T| <= t)`` for Student's t with ``df`` (>= 1) degrees of freedom and ``t`` >= 0: the
    finite sums of Abramowitz and Stegun 26.7.3-4 in ``theta = atan(t / sqrt(df))``, exact for an
    integer ``df``."""
    theta = math.atan(t / math.sqrt(df))
    c2 = math.cos(theta) ** 2
    if df % 2 == 1:
        term, total = math.cos(theta), 0.0
        for k in range(1, (df - 1) // 2 + 1):  # cos, (2/3) cos^3, (2 4 / 3 5) cos^5, ...
            total += term
            term *= c2 * (2 * k) / (2 * k + 1)
        return (2.0 / math.pi) * (theta + math.sin(theta) * total)
    term, total = 1.0, 0.0
    for k in range(1, df // 2 + 1):  # 1, (1/2) cos^2, (1 3 / 2 4) cos^4, ...
        total += term
        term *= c2 * (2 * k - 1) / (2 * k)
    return math.sin(theta) * total


def t_quantile(p: float, df: int) -> float:
    """The ``p`` quantile (``p`` in (0.5, 1)) of Student's t with ``df`` (>= 1) degrees of freedom,
    by bisection of :func:`t_probability` to 1e-10 (scipy.stats.t.ppf without scipy: the train extra
    does not install it); above 100,000 degrees of freedom the normal quantile."""
    if not 0.5 < p < 1.0 or df < 1:
        raise ValueError(f"t_quantile: p = {p}, df = {df} are out of range: p in (0.5, 1), df >= 1")
    if df > 100_000:
        return float(NormalDist().inv_cdf(p))
    low, high, two_sided = 0.0, 1.0, 2.0 * p - 1.0
    while t_probability(high, df) < two_sided:
        high *= 2.0
    while high - low > 1e-10 * max(high, 1.0):
        mid = 0.5 * (low + high)
        low, high = (mid, high) if t_probability(mid, df) < two_sided else (low, mid)
    return 0.5 * (low + high)


def table(scores: Sequence[Score]) -> str:
    """Markdown table of scores."""
    lines = [
        "| policy | episodes | apex error (mean +- 95 % CI) | apexes within 5 % | apexes per episode "
        "| episode length | return |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for s in scores:
        lines.append(
            f"| {s.policy} | {s.episodes} | {s.apex_error:.3f} +- {s.apex_error_ci95:.3f} | "
            f"{100 * s.success_rate:.1f} % | {s.apexes:.1f} | {s.episode_length:.0f} | "
            f"{s.episode_return:.2f} |"
        )
    return "\n".join(lines)


def build_parser() -> argparse.ArgumentParser:
    """The command line of ``python -m agents.evaluate`` / ``ballenv-evaluate``."""
    parser = argparse.ArgumentParser(prog="ballenv-evaluate", description=__doc__.split("\n")[0])
    parser.add_argument("policy", help=f"one of {NAMED_POLICIES}, a model .zip or a run folder of train.py")
    parser.add_argument("--action-mode", choices=("pressure", "paddle"), help="shortcut for env_kwargs")
    parser.add_argument("--env-kwargs", type=parse_env_kwargs, default=None, help="JSON object")
    parser.add_argument("--episodes", type=int, default=20, help="held-out episodes (default 20)")
    parser.add_argument("--seed", type=int, default=DEFAULT_SEED, help="seed of the first episode")
    parser.add_argument("--algo", choices=("ppo", "sac"), help="algorithm of a bare model .zip")
    parser.add_argument("--json", help="also write the score to this file")
    parser.add_argument(
        "--trust", action="store_true",
        help="load a run folder or model this user's training did not write (a saved model is a "
        "pickle: it runs the code it carries; use only for files from a source you trust)",
    )  # fmt: skip
    return parser


def main(argv: Sequence[str] | None = None) -> None:
    parser = build_parser()
    args = parser.parse_args(argv)
    env_kwargs = dict(args.env_kwargs or {})
    if args.env_kwargs is None and args.policy not in NAMED_POLICIES:
        env_kwargs = _run_env_kwargs(args.policy)
    elif args.env_kwargs is None:  # a baseline: on the task the agents of its mode train on
        env_kwargs = task_env_kwargs("ppo", args.action_mode or "pressure")
    if args.action_mode:
        env_kwargs["action_mode"] = args.action_mode
    try:
        score = evaluate(
            args.policy, env_kwargs, args.episodes, args.seed, args.algo, progress=True, trust=args.trust
        )
    except ValueError as err:  # a policy or env keyword the user mistyped
        parser.error(str(err))
    print(table([score]))
    if args.json:
        write_text(args.json, json.dumps(asdict(score), indent=2))


def _run_env_kwargs(policy: str) -> dict[str, Any]:
    """The env keyword arguments a run folder of train.py was trained with (else none)."""
    import pathlib

    import yaml

    path = pathlib.Path(policy)
    config = (path if path.is_dir() else path.parent) / "config.yml"
    if not config.exists():
        return {}
    return dict(yaml.safe_load(config.read_text()).get("env_kwargs") or {})


if __name__ == "__main__":
    main()
