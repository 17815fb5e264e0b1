"""Behaviour cloning from the privileged lookahead: demonstrations of a bounce-level task, and a
Stable-Baselines3 PPO policy pretrained on them before reinforcement learning.

    python -m agents.imitation --wrapper agents.wrappers.PumpApex --out runs/demonstrations_pump.npz
    python train.py --algo ppo --action-mode pressure --conf-file ppo_cloned \
        --demonstrations runs/demonstrations_pump.npz   # agents/hyperparams/ppo_cloned.yml

The tasks (``TASKS``) take one action per bounce: :class:`agents.wrappers.PumpApex` (or
``PumpAmplitude``, the same task summing the env's rewards) the pump's amplitude ``u =
AMPLITUDE_SPAN a`` in the pressure mode, :class:`agents.wrappers.PaddleStrike` a correction of the
scripted paddle's strike in the paddle mode. At each of the task's decisions the mode's lookahead
(:class:`agents.lookahead.LookaheadPump`, :class:`agents.lookahead.LookaheadPaddle`) tries 41
candidates on copies of the simulator (around what the agent's zero action plays, the wrapper's
``base``); the demonstration's action is the lookahead's label (``label``) where the next apex's
signed error crosses zero (the pump: :func:`agents.lookahead.zero_crossing`, linear between the two
candidates around it; the paddle, whose bounce scatters between nearby strikes: where the
least-squares line through the errors does, :func:`agents.lookahead.trend_crossing`), or the best
candidate where none crosses, as the agent's action (the wrapper's ``action_for``). The
demonstrator plays its actions, so the recorded states are the ones it visits. The lookahead reads
the simulator; the policy cloned from it reads only the wrapper's observation (the ball as a body
and, in the pressure mode, its landing phase, 11 entries; in the paddle mode its landing rotation
phase, its rotation phase and spin at the strike and the scripted strike, 26 entries).

:func:`pretrain` fits the policy's mean action to the demonstrations (mean squared error), its value
to the discounted return of the demonstrator's normalised rewards (an episode cut short by the time
limit continues with the value of its last state: :func:`discounted_returns`, refitted
``VALUE_ROUNDS`` times), and starts the observation and reward normalisation (``VecNormalize``) from the
demonstrations' statistics, so reinforcement learning starts from the cloned policy.
"""

from __future__ import annotations

import argparse
import pathlib
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .config import ENV_ID, task_env_kwargs
from .lookahead import lookahead_for
from .wrappers import wrapper_class

if TYPE_CHECKING:
    import torch
    from stable_baselines3.common.base_class import BaseAlgorithm
    from stable_baselines3.common.vec_env import VecEnv

# the tasks to demonstrate: wrapper -> the action mode it plays
TASKS = {
    "agents.wrappers.PumpApex": "pressure",
    "agents.wrappers.PumpAmplitude": "pressure",
    "agents.wrappers.PaddleStrike": "paddle",
}
WRAPPERS = tuple(TASKS)
EPOCHS = 3000  # at most, full batch; stopped early on held-back samples
PATIENCE = 200  # epochs without a better held-back loss that stop a fit
VALUE_ROUNDS = 5  # regressions of the value on the returns, each bootstrapped by the last


@dataclass(frozen=True)
class Demonstrations:
    """The demonstrator's transitions, one per bounce, behind the wrapper named ``wrapper`` (one of
    ``WRAPPERS``): wrapped observations (n, k), actions (n, 1) in [-1, 1], the wrapper's rewards
    (n,), the next observations (n, k) and whether the episode terminated there (n,) or ended at
    all (n,: terminated or truncated)."""

    wrapper: str
    observations: NDArray[np.float32]
    actions: NDArray[np.float32]
    rewards: NDArray[np.float64]
    next_observations: NDArray[np.float32]
    terminated: NDArray[np.bool_]
    ended: NDArray[np.bool_]

    def save(self, path: str | pathlib.Path) -> None:
        np.savez(path, **self.__dict__)

    @classmethod
    def concatenate(cls, parts: Sequence[Demonstrations]) -> Demonstrations:
        """The demonstrations of ``parts`` (of one task) one after the other."""
        wrappers = {d.wrapper for d in parts}
        if len(wrappers) != 1:
            raise ValueError(f"demonstrations of several tasks ({sorted(wrappers)}) cannot be joined")
        names = [name for name in cls.__dataclass_fields__ if name != "wrapper"]
        arrays = {name: np.concatenate([getattr(d, name) for d in parts]) for name in names}
        return cls(parts[0].wrapper, **arrays)

    @classmethod
    def load(cls, path: str | pathlib.Path) -> Demonstrations:
        """The demonstrations saved in ``path``; a ``ValueError`` if their task is not one of
        ``WRAPPERS``."""
        with np.load(path) as data:
            fields = {name: data[name] for name in cls.__dataclass_fields__}
        wrapper = str(fields["wrapper"])
        if wrapper not in WRAPPERS:
            raise ValueError(f"wrapper = {wrapper!r} is invalid: the demonstrated tasks are {WRAPPERS}")
        return cls(**{**fields, "wrapper": wrapper})


def record(
    env_kwargs: dict[str, Any],
    episodes: int,
    seed: int = 0,
    wrapper: str = WRAPPERS[0],
    progress: bool = True,
) -> Demonstrations:
    """The lookahead's demonstrations over ``episodes`` episodes reset with seeds ``seed``,
    ``seed + 1``, ... (training seeds: held-out evaluation starts at 10,000), behind ``wrapper``
    (one of ``WRAPPERS``)."""
    import gymnasium as gym
    from tqdm.auto import tqdm

    task = wrapper_class(wrapper) if wrapper in WRAPPERS else None
    if task is None:
        raise ValueError(f"wrapper = {wrapper!r} is invalid: the demonstrated tasks are {WRAPPERS}")
    env: Any = task(gym.make(ENV_ID, **{**env_kwargs, "action_mode": TASKS[wrapper]}))  # base, action_for
    lookahead = lookahead_for(env)  # the pump's candidates span the task's AMPLITUDE_SPAN
    columns: dict[str, list[Any]] = {
        name: [] for name in Demonstrations.__dataclass_fields__ if name != "wrapper"
    }
    for episode in tqdm(range(episodes), desc="lookahead demonstrations", disable=not progress):
        obs, _ = env.reset(seed=seed + episode)
        done = False
        while not done:
            best = lookahead.plan(env.base)  # around the value the agent's zero action plays
            crossing = lookahead.label()
            action = float(np.clip(env.action_for(crossing if np.isfinite(crossing) else best), -1.0, 1.0))
            next_obs, reward, terminated, truncated, _ = env.step(np.array([action], dtype=np.float32))
            done = terminated or truncated
            row = (obs, [action], float(reward), next_obs, terminated, done)
            for name, value in zip(columns, row, strict=True):
                columns[name].append(value)
            obs = next_obs
    env.close()
    arrays = {name: np.asarray(values) for name, values in columns.items()}
    arrays["observations"] = arrays["observations"].astype(np.float32)
    arrays["next_observations"] = arrays["next_observations"].astype(np.float32)
    arrays["actions"] = arrays["actions"].astype(np.float32)
    return Demonstrations(wrapper, **arrays)


def record_in_parallel(
    env_kwargs: dict[str, Any],
    episodes: int,
    seed: int = 0,
    wrapper: str = WRAPPERS[0],
    workers: int = 1,
) -> Demonstrations:
    """:func:`record`'s demonstrations of episodes ``seed .. seed + episodes - 1``, in ``workers``
    spawned processes, each recording a contiguous share of the seeds: the same arrays, in the same
    order, as one :func:`record` of them all (an episode depends on its seed only)."""
    workers = max(1, min(workers, episodes))
    if workers == 1:
        return record(env_kwargs, episodes, seed, wrapper)
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    bounds = np.linspace(0, episodes, workers + 1).round().astype(int)
    shares = [(int(a), int(b - a)) for a, b in zip(bounds[:-1], bounds[1:], strict=True) if b > a]
    context = multiprocessing.get_context("spawn")  # no fork of a process holding torch's threads
    with ProcessPoolExecutor(len(shares), mp_context=context) as pool:
        jobs = [pool.submit(record, env_kwargs, n, seed + a, wrapper, False) for a, n in shares]
        parts = [job.result() for job in jobs]
    return Demonstrations.concatenate(parts)


def regress(
    params: Sequence[torch.nn.Parameter],
    loss: Callable[[NDArray[np.int64]], torch.Tensor],
    n: int,
    seed: int = 0,
    learning_rate: float = 1e-3,
) -> float:
    """Fit ``params`` by full-batch Adam (``learning_rate``, weight decay 1e-4) on ``loss(indices)``
    (the mean loss of those samples of ``0 .. n - 1``), over the samples but a sixth held back,
    stopped where the held-back loss has not improved for ``PATIENCE`` epochs (at most ``EPOCHS``);
    the parameters end at their best held-back loss, which is returned."""
    import torch

    order = np.random.default_rng(seed).permutation(n)
    held, fitted = order[: max(n // 6, 1)], order[max(n // 6, 1) :]
    optimiser = torch.optim.Adam(params, lr=learning_rate, weight_decay=1e-4)
    best, best_values, waited = np.inf, [p.detach().clone() for p in params], 0
    for _ in range(EPOCHS):
        optimiser.zero_grad()
        loss(fitted).backward()
        optimiser.step()
        with torch.no_grad():
            held_loss = float(loss(held))
        if held_loss < best:
            best, best_values, waited = held_loss, [p.detach().clone() for p in params], 0
        elif (waited := waited + 1) > PATIENCE:
            break
    with torch.no_grad():
        for p, value in zip(params, best_values, strict=True):
            p.copy_(value)
    return best


def pretrain(model: BaseAlgorithm, envs: VecEnv, demonstrations: Demonstrations) -> dict[str, float]:
    """Clone the demonstrations into ``model`` (an SB3 PPO) trained on ``envs`` (see the module doc);
    returns the held-back mean squared errors of the action (in [-1, 1] units) and of the value."""
    import torch
    from stable_baselines3.common.vec_env import VecNormalize

    policy = model.policy
    gamma = float(getattr(model, "gamma", 0.99))
    obs: Any = demonstrations.observations
    next_obs: Any = demonstrations.next_observations
    rewards = demonstrations.rewards
    if isinstance(envs, VecNormalize):
        start_normalisation(envs, demonstrations, gamma)
        obs, next_obs = envs.normalize_obs(obs), envs.normalize_obs(next_obs)
        rewards = envs.normalize_reward(rewards)
    x, x_next = torch.as_tensor(obs, dtype=torch.float32), torch.as_tensor(next_obs, dtype=torch.float32)
    actions = torch.as_tensor(demonstrations.actions, dtype=torch.float32)
    n = len(actions)

    def mean_action(rows: NDArray[np.int64]) -> torch.Tensor:
        return policy.get_distribution(x[rows]).distribution.mean

    def value(rows: NDArray[np.int64]) -> torch.Tensor:
        return policy.predict_values(x[rows])[:, 0]

    actor = [*policy.mlp_extractor.policy_net.parameters(), *policy.action_net.parameters()]
    action_error = regress(actor, lambda rows: ((mean_action(rows) - actions[rows]) ** 2).mean(), n)
    critic = [*policy.mlp_extractor.value_net.parameters(), *policy.value_net.parameters()]
    cut_short = demonstrations.ended & ~demonstrations.terminated  # truncated: the value goes on
    value_error = np.inf
    target = torch.zeros(n)

    def value_loss(rows: NDArray[np.int64]) -> torch.Tensor:
        return ((value(rows) - target[rows]) ** 2).mean()

    for _ in range(VALUE_ROUNDS):
        with torch.no_grad():
            tail = np.where(cut_short, policy.predict_values(x_next)[:, 0].numpy(), 0.0)
        target = torch.as_tensor(discounted_returns(rewards, demonstrations.ended, tail, gamma))
        value_error = regress(critic, value_loss, n)
    return {"action_mse": action_error, "value_mse": value_error}


def discounted_returns(
    rewards: NDArray[np.float64], ended: NDArray[np.bool_], tail: NDArray[np.float64], gamma: float
) -> NDArray[np.float32]:
    """Per transition ``t`` of episodes laid end to end (``ended``: the last of each), its return
    ``G_t = r_t + gamma G_{t+1}``, with ``G`` after an episode's last transition ``tail`` there (the
    value of the state a truncated episode stopped in; 0 after a termination)."""
    returns, running = np.empty(len(rewards), dtype=np.float32), 0.0
    for t in range(len(rewards) - 1, -1, -1):
        running = rewards[t] + gamma * (tail[t] if ended[t] else running)
        returns[t] = running
    return returns


def start_normalisation(envs: Any, demonstrations: Demonstrations, gamma: float) -> None:
    """Update ``envs``' (a ``VecNormalize``) running statistics with the demonstrations: the
    observations', and the discounted returns' that scale its rewards (``R_t = gamma R_{t-1} + r_t``,
    restarted at each episode's end, as ``VecNormalize`` tracks them)."""
    envs.obs_rms.update(demonstrations.observations.astype(np.float64))
    returns, running = np.empty(len(demonstrations.rewards)), 0.0
    for t, (reward, ended) in enumerate(zip(demonstrations.rewards, demonstrations.ended, strict=True)):
        running = gamma * running + reward
        returns[t] = running
        running = 0.0 if ended else running
    envs.ret_rms.update(returns)


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--episodes", type=int, default=100, help="demonstrated episodes (about 2 s each)")
    p.add_argument("--seed", type=int, default=0, help="seed of the first episode (held-out: 10,000 on)")
    p.add_argument("--wrapper", choices=WRAPPERS, default=WRAPPERS[0], help="the task (its reward)")
    p.add_argument("--out", default="runs/demonstrations.npz", help="where to write them")
    args = p.parse_args(argv)
    if args.episodes < 1:
        p.error(f"--episodes = {args.episodes} is invalid: must be >= 1")
    return args


def main(argv: Sequence[str] | None = None) -> None:
    """``python -m agents.imitation``: record the lookahead's demonstrations to ``--out``."""
    args = parse_args(argv)
    env_kwargs = task_env_kwargs("ppo", TASKS[args.wrapper])
    demonstrations = record(env_kwargs, args.episodes, args.seed, args.wrapper)
    out = pathlib.Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    demonstrations.save(out)
    print(
        f"wrote {len(demonstrations.actions)} bounces of {args.episodes} episodes to {out}", file=sys.stderr
    )


if __name__ == "__main__":
    main()
