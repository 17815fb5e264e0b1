"""Score a policy on the 3-D ball (InflatedBall3DPaddle-v0 or InflatedBall3D-v0) over episodes:
how close its flight apexes come to the target height and, in paddle mode, to the target spot.

    python -m agents.evaluate3d heuristic --episodes 20          # the tuned dribbler, paddle mode
    python -m agents.evaluate3d idle --action-mode pressure --max-episode-steps 300
    python -m agents.evaluate3d runs/ppo_paddle3d_seed0      # a run folder of train.py (its best model)

Episode ``k`` is reset with seed ``seed + k`` (default 10,000 on, held out: the tuning uses 0, 1,
...), so the same arguments give the same numbers. Per episode (:class:`Score3D`):

* **height error**: the mean over its flight apexes of ``|h - h_t| / h_t``;
* **spot distance** (m): the mean over the same apexes of the centre's horizontal distance to the
  target spot at the apex (paddle mode; 0 in pressure mode);
* **combined error**: ``height error / reward_margin + spot distance / spot_margin``, each error in
  units of the env's reward margin for it (where its reward term falls to 0.1: 0.5 and 0.3 m by
  default), so both weigh as the reward weighs them.

Each apex missed because the episode ended early (the ball came to rest, left the arena or the
simulator failed) counts a height error of 1 and the spot distance where the episode ended: one per
flight time ``2 sqrt(2 (h_t - R) / g)`` left until the time limit, as ``agents.evaluate`` counts them.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from ballenv.envs import BALL3D_ENV_IDS
from ballenv.envs.ball3d.config import Ball3DConfig
from ballenv.envs.ball3d.env import ball3d_env

from .baselines import ModelPolicy
from .evaluate import missed_apexes
from .policies import Heuristic3DPolicy, IdlePolicy, Policy, RandomPolicy

DEFAULT_SEED = 10_000
POLICIES: dict[str, Callable[[gym.Env[Any, Any]], Policy]] = {
    "heuristic": Heuristic3DPolicy,
    "idle": IdlePolicy,
    "random": RandomPolicy,
}


@dataclass(frozen=True)
class Score3D:
    """One policy's episodes (each tuple in seed order; the module doc defines the errors)."""

    policy: str
    height_errors: tuple[float, ...]  # per episode, relative
    spot_distances: tuple[float, ...]  # per episode, m
    combined_errors: tuple[float, ...]  # per episode, in reward margins
    apexes: tuple[int, ...]  # per episode, missed ones included
    lengths: tuple[int, ...]  # control steps
    returns: tuple[float, ...]


class Apex(NamedTuple):
    """One flight apex of an episode (the module doc's errors)."""

    height: float  # |h - h_t| / h_t; 1 for a missed apex
    distance: float  # m: the centre's horizontal distance to the target spot (0 in pressure mode)
    step: int  # the control steps taken when it was seen (the episode's length for a missed apex)


def apex_records(env: gym.Env[Any, Any], policy: Policy, seed: int) -> tuple[list[Apex], int, float]:
    """One episode: (its apexes, missed ones appended; its length in control steps; its return)."""
    obs, _ = env.reset(seed=seed)
    policy.reset(seed)
    ball = ball3d_env(env)
    structure, config = ball.observation_structure, ball.config
    limit = env.spec.max_episode_steps if env.spec and env.spec.max_episode_steps else None
    apexes: list[Apex] = []
    total, length = 0.0, 0
    while True:
        obs, reward, terminated, truncated, info = env.step(policy.act(obs))
        total, length = total + float(reward), length + 1
        distance = spot_distance(obs, structure) if config.paddle else 0.0
        if info["apex_count"]:
            height = abs(info["apex_height"] - info["target_height"]) / info["target_height"]
            apexes.append(Apex(height, distance, length))
        if terminated and limit:
            missed = missed_apexes(config, info["target_height"], (limit - length) * config.control_dt)
            apexes += [Apex(1.0, distance, length)] * missed
        if terminated or truncated:
            return apexes, length, total


def run_episode(
    env: gym.Env[Any, Any], policy: Policy, seed: int
) -> tuple[list[float], list[float], int, float]:
    """One episode: (each apex's relative height error, each apex's spot distance in m, missed
    ones appended; its length in control steps; its return)."""
    apexes, length, total = apex_records(env, policy, seed)
    return [a.height for a in apexes], [a.distance for a in apexes], length, total


def spot_distance(obs: NDArray[np.float32], structure: dict[str, slice]) -> float:
    """The centre's horizontal distance (m) to the target spot in observation ``obs``."""
    offset = obs[structure["centre_of_mass_position"]][:2] - obs[structure["target_spot"]]
    return float(np.hypot(*offset))


def combined_error(config: Ball3DConfig, height: float, distance: float) -> float:
    """The combined error of a relative ``height`` error and a spot ``distance`` (m) (module doc;
    the distance counts in paddle mode only)."""
    return height / config.reward_margin + (distance / config.spot_margin if config.paddle else 0.0)


def evaluate3d(
    policy: str | Callable[[gym.Env[Any, Any]], Policy],
    env_kwargs: dict[str, Any] | None = None,
    episodes: int = 20,
    seed: int = DEFAULT_SEED,
) -> Score3D:
    """Score ``policy`` (a name of :data:`POLICIES`, a saved model or run folder of train.py, or a
    callable ``env -> policy``) over ``episodes``
    episodes of the 3-D env of ``env_kwargs`` (``action_mode`` picks the id, default paddle; the
    rest, ``max_episode_steps`` included, go to ``gym.make``) seeded ``seed, seed + 1, ...``."""
    kwargs = dict(env_kwargs or {})
    mode = kwargs.pop("action_mode", "paddle")
    env = gym.make(f"ballenv:{BALL3D_ENV_IDS[mode]}", **kwargs)
    agent = _policy(policy, env)
    config = ball3d_env(env).config
    rows = []
    for s in range(seed, seed + episodes):
        heights, spots, length, total = run_episode(env, agent, s)
        h = float(np.mean(heights)) if heights else 1.0
        d = float(np.mean(spots)) if spots else 0.0
        combined = combined_error(config, h, d)
        rows.append((h, d, combined, len(heights), length, total))
    env.close()
    columns = list(zip(*rows, strict=True))
    return Score3D(
        agent.name, tuple(columns[0]), tuple(columns[1]), tuple(columns[2]),
        tuple(int(n) for n in columns[3]), tuple(int(n) for n in columns[4]), tuple(columns[5]),
    )  # fmt: skip


def _policy(spec: str | Callable[[gym.Env[Any, Any]], Policy], env: gym.Env[Any, Any]) -> Policy:
    """The policy ``spec`` names (:func:`evaluate3d`) on ``env``."""
    if callable(spec):
        return spec(env)
    if spec in POLICIES:
        return POLICIES[spec](env)
    model = ModelPolicy(env, spec)
    model.name = f"trained ({spec})"
    return model


def build_parser() -> argparse.ArgumentParser:
    """The command line of ``python -m agents.evaluate3d``."""
    p = argparse.ArgumentParser(prog="python -m agents.evaluate3d", description=__doc__.split("\n")[0])
    p.add_argument(
        "policy", help=f"one of {sorted(POLICIES)} (heuristic: the tuned scripted controller), or a run "
        "folder or model .zip of train.py",
    )  # fmt: skip
    p.add_argument("--action-mode", choices=("pressure", "paddle"), default="paddle")
    p.add_argument("--episodes", type=int, default=20, help="episodes (default 20)")
    p.add_argument("--seed", type=int, default=DEFAULT_SEED, help="seed of the first episode")
    p.add_argument("--max-episode-steps", type=int, default=None, help="time limit (default the id's, 1000)")
    return p


def main(argv: Sequence[str] | None = None) -> None:
    args = build_parser().parse_args(argv)
    kwargs: dict[str, Any] = {"action_mode": args.action_mode}
    if args.max_episode_steps:
        kwargs["max_episode_steps"] = args.max_episode_steps
    s = evaluate3d(args.policy, kwargs, args.episodes, args.seed)
    print(
        f"{s.policy}: height error {np.mean(s.height_errors):.3f}, spot distance "
        f"{np.mean(s.spot_distances):.3f} m, combined {np.mean(s.combined_errors):.3f} (means of "
        f"{args.episodes} episodes); {np.mean(s.apexes):.1f} apexes, {np.mean(s.lengths):.0f} steps"
    )


if __name__ == "__main__":
    main()
