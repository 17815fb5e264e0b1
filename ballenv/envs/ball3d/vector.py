"""A native vector env of InflatedBall3D-v0: the balls stepped on threads.

``gym.make_vec("InflatedBall3DPaddle-v0", num_envs=8)`` (the ids' default vectorisation). Env ``i``
uses the random stream of a single env reset with ``seed + i`` (as ``SyncVectorEnv`` seeds its envs)
and the same steps, so it reproduces single envs to the bit, whatever the thread count. The
simulator's implicit step releases Python's lock, so ``num_threads`` threads may overlap in it
(the rest of a control step, the env's Python, runs one thread at a time;
``benchmarks/results/env3d_throughput.md`` has what two threads gain). Autoreset
follows Gymnasium's default ``NEXT_STEP`` mode: the step after an episode ends resets that env,
ignores its action and returns the first observation of the new episode with reward 0.

| Keyword | Default | Description |
|---|---|---|
| num_envs | 1 | envs stepped together (int in [1, 10000]) |
| max_episode_steps | 1000 | control steps after which an env's episode is truncated |
| num_threads | the cores, at most num_envs | threads stepping the envs |
| the env's keywords | as InflatedBall3D-v0 | ``action_mode``, ``fidelity``, ...: the same for every env |
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space
from numpy.typing import ArrayLike, NDArray

from ..config import check_reset, parse_actions
from . import observation
from .ball import Ball
from .config import ENV_NAME, Ball3DConfig

DEFAULT_MAX_EPISODE_STEPS = 1000
MAX_ENVS = 10_000


def _count(name: str, value: object, low: int, high: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise ValueError(
            f"{ENV_NAME}.{name} = {value!r} is out of range: must be an integer in [{low}, {high}]"
        )
    return value


class Ball3DVectorEnv(VectorEnv[NDArray[np.float32], NDArray[np.float32], NDArray[Any]]):
    """``num_envs`` InflatedBall3D-v0 episodes advanced together on ``num_threads`` threads (module
    doc; the task, spaces and keywords: :class:`~ballenv.envs.ball3d.env.InflatedBall3DEnv`)."""

    metadata = {"render_modes": [], "render_fps": 100.0, "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(
        self,
        num_envs: int = 1,
        max_episode_steps: int = DEFAULT_MAX_EPISODE_STEPS,
        num_threads: int | None = None,
        **kwargs: Any,
    ) -> None:
        self.num_envs = _count("num_envs", num_envs, 1, MAX_ENVS)
        self.max_episode_steps = _count("max_episode_steps", max_episode_steps, 1, 10**9)
        cores = os.cpu_count() or 1
        threads = min(cores, num_envs) if num_threads is None else num_threads
        self.num_threads = _count("num_threads", threads, 1, 1024)
        self.config = Ball3DConfig.from_kwargs(kwargs)
        self.balls = [Ball(self.config) for _ in range(num_envs)]
        low, high = observation.bounds(self.config)
        self.single_observation_space = spaces.Box(low, high, dtype=np.float32)
        n_actions = 3 if self.config.paddle else 1
        self.single_action_space = spaces.Box(-1.0, 1.0, shape=(n_actions,), dtype=np.float32)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self._rngs = [seeding.np_random()[0] for _ in range(num_envs)]
        self._autoreset = np.zeros(num_envs, dtype=np.bool_)
        self._pool = ThreadPoolExecutor(self.num_threads) if self.num_threads > 1 else None
        self._has_reset = False
        self.metadata = {**self.metadata, "render_fps": self.config.control_frequency}

    @property
    def observation_structure(self) -> dict[str, slice]:
        """Name -> slice of each env's observation vector (a new dict)."""
        return observation.structure(self.config.n_vertices, self.config.paddle)

    def reset(
        self, *, seed: int | Sequence[int | None] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[NDArray[np.float32], dict[str, Any]]:
        super().reset(seed=seed if isinstance(seed, int) else None)
        if seed is None or isinstance(seed, int):
            seeds: list[int | None] = [None if seed is None else seed + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise ValueError(
                    f"{ENV_NAME} vector reset seed has {len(seeds)} entries: must have "
                    f"num_envs = {self.num_envs}"
                )
        for i, s in enumerate(seeds):
            self._rngs[i], _ = seeding.np_random(s)
            self.balls[i].reset(self._rngs[i])
        self._autoreset[:] = False
        self._has_reset = True
        return self._observations(), self._infos()

    def step(
        self, actions: ArrayLike
    ) -> tuple[
        NDArray[np.float32], NDArray[np.float64], NDArray[np.bool_], NDArray[np.bool_], dict[str, Any]
    ]:
        check_reset(self._has_reset, "vector step", ENV_NAME)
        n = 3 if self.config.paddle else 1
        a = np.clip(parse_actions(actions, self.num_envs * n, "vector step actions", ENV_NAME), -1.0, 1.0)
        a = a.reshape(self.num_envs, n)
        resetting = self._autoreset.copy()

        def advance(i: int) -> None:
            if resetting[i]:
                self.balls[i].reset(self._rngs[i])
            else:
                self.balls[i].act(a[i])

        # one task per env, taken by whichever thread is free: a ball in contact takes many short
        # steps while one in flight takes one, so fixed shares would leave a thread idle
        if self._pool is None:
            for i in range(self.num_envs):
                advance(i)
        else:
            list(self._pool.map(advance, range(self.num_envs)))
        stepped = ~resetting
        terminated = np.array([b.end != "" for b in self.balls]) & stepped
        truncated = np.array([b.steps >= self.max_episode_steps for b in self.balls]) & stepped
        reward = np.where(stepped, [b.reward[0] for b in self.balls], 0.0)
        self._autoreset = terminated | truncated
        return self._observations(), reward, terminated, truncated, self._infos()

    def _observations(self) -> NDArray[np.float32]:
        return np.stack([b.observe() for b in self.balls])

    def _infos(self) -> dict[str, Any]:
        """Each key of a single env's ``info``, as an array over the envs."""
        rows = [b.info() for b in self.balls]
        return {key: np.array([row[key] for row in rows]) for key in rows[0]}

    def close_extras(self, **kwargs: Any) -> None:
        if self._pool is not None:
            self._pool.shutdown()
            self._pool = None
